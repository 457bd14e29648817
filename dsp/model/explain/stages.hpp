#pragma once
// The stages of eical explain (explain.hpp), each a function of the state they share: the
// run's residuals and the effects found so far. explain_run calls them in a flat list.
#include "dsp/core/run.hpp"
#include "dsp/model/acceleration_comparison.hpp"
#include "dsp/model/effect_catalog.hpp"
#include "dsp/model/effects.hpp"
#include "dsp/model/explain.hpp"
#include "dsp/model/run_residuals.hpp"
#include "dsp/model/stick_slip_bursts.hpp"
#include "dsp/model/structural_modes.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace eical::dsp::model::stage {

// Jackknife blocks of the machine channel: half a second, several per move.
inline constexpr double kJackknifeBlockS = 0.5;
// What the rest before a move leaves the bias uncertain by (≈ 0.3 µg: the noise over a
// few tenths of a second of rest), µm/s².
inline constexpr double kNominalBiasStepUmS2 = 3.0;
// A known effect (the Earth rate) is named when the run favours it: 2 ln(likelihood ratio)
// above 2, "positive" evidence on the Kass–Raftery scale.
inline constexpr double kKnownEffectEvidence = 2.0;
// What an effect outside the table must explain to be named: half the instrument's 1 µm.
inline constexpr double kMaterialUm = 0.5;
// Structural modes of machine tools lie below this; a response feature above it is the
// sensors' and the DAQ's business.
inline constexpr double kModeMaxHz = 300.0;

struct ExplainState {
  const Run& run;
  const ExplainOptions& options;
  RunResiduals rr;
  LagColumns lag;                    // each axis' loop (the base model of reference − set-point)
  std::vector<EffectModel> machine;  // the machine effects' columns, shapes chosen on this run
  std::array<bool, 3> cmd_axes{};    // moving axes with the set-point as their only reference
  std::vector<ExplainedEffect> effects;
  RunExplanation ex;
  std::vector<StructuralMode> modes;  // significant modes the motion drives (test_vibration)
  StickSlipFinding stick_slip;        // test_stick_slip
  bool integration_supported = true;  // a rest or a position support holds the double integral
  // What the accepted effects leave, for the unexplained-residual test.
  struct Leftover {
    double held_rms_um = 0.0, held_expected_rms_um = 0.0;  // the integrated motion at the held-out points
    double machine_rms_um = 0.0, machine_noise_um = 0.0;   // reference − set-point
    Eigen::VectorXd machine_residual;
    const Channel* machine_rows = nullptr;
    // The residual is what the base model and the whole table leave: an orthonormal basis
    // of their weighted columns, and the rows' σ. A model sought in it afterwards (a mode)
    // must leave the same columns out of its own (machine_projected), or the table's fit
    // keeps part of its signal and the search chases the rest (Frisch–Waugh–Lovell).
    Eigen::MatrixXd machine_basis;
    Eigen::VectorXd machine_sigma_um;
  } leftover;

  // A column on the machine rows (µm) as the residual sees it: weighted, the base model and
  // the table left out, back in µm. Unchanged when no basis was kept.
  [[nodiscard]] Eigen::VectorXd machine_projected(const Eigen::VectorXd& column_um) const;

  ExplainedEffect* find(std::string_view name);
  [[nodiscard]] const ExplainedEffect* find(std::string_view name) const;
  // An effect found twice (two channels, two tests) is kept once: the significant or more
  // important finding, with the other's parameters added.
  void merge(ExplainedEffect e);
};

void merge(std::vector<ExplainedEffect>& all, ExplainedEffect e);

// "x", "y", "z" (built from std::string(1, c): GCC 12 warns falsely on string + char).
inline std::string axis_letter(int a) { return std::string(1, "xyz"[a]); }

// An effect of the catalogue with its name, unit and tolerance, nothing found yet.
ExplainedEffect effect_of(Effect e);

// printf into a string (numbers only).
template <typename... Num>
std::string fmt(const char* f, Num... v) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, static_cast<double>(v)...);
  return buf;
}

// A value moved by `shift` (k standard errors) towards zero, to zero when within it: the
// size that lies outside a band with confidence; and moved as far away from zero. Every
// σ-shifted size (the maps below, a channel's parameter vectors) is made by these two.
inline double toward_zero(double value, double shift) {
  return std::abs(value) > shift ? value - std::copysign(shift, value) : 0.0;
}
inline double away_from_zero(double value, double shift) { return value + std::copysign(shift, value); }

// Each value moved k standard errors towards zero (to zero when within them).
std::map<std::string, double> toward_zero(const std::map<std::string, double>& value,
                                          const std::map<std::string, double>& sigma, double k = 2.0);

// The same moved k standard errors away from zero: with toward_zero, the interval whose
// magnitudes give the size's own σ (magnitude_sigma).
std::map<std::string, double> away_from_zero(const std::map<std::string, double>& value,
                                             const std::map<std::string, double>& sigma, double k = 2.0);

// σ of a size from its magnitude at the fitted values and at the values moved 2σ towards
// and away from zero: the wider half-interval, halved.
double magnitude_sigma(double magnitude, double toward, double away);

// A parameter fitted per axis ("name@x", "name@y") as one value: their mean (nullopt: none).
std::optional<double> axes_mean(const std::map<std::string, double>& value, const std::string& name);

// An effect's columns on a channel's rows (µm per unit).
Eigen::MatrixXd columns_on(const EffectModel& e, const Channel& ch);
// One mode's columns on a channel's rows (µm per unit gain): its displacement response to
// each moving axis' commanded acceleration and jerk, per measured axis.
std::vector<Eigen::VectorXd> mode_displacement_columns(const RunResiduals& rr, const Channel& rows, double f_hz,
                                                       double zeta);
// A channel's residual with each axis' offset taken out (the reference's zero is arbitrary).
Eigen::VectorXd offsets_out(const Channel& ch);
// RMS over the rows of the axes the program moves.
double moving_axes_rms(const RunResiduals& rr, const Eigen::VectorXd& v, const Channel& ch);
// The run with the sensor-side extensions of `taken` in its meta.
Run extended_run(const Run& run, const std::vector<ExplainedEffect>& taken);

// The stages, in the order explain_run calls them.
ExplainState prepare(const Run& run, const ExplainOptions& options);
void fit_integrated_motion(
    ExplainState& st);  // sensor effects (and set-point-only machine ones) through the integration's filter
void test_vibration(ExplainState& st);          // spectra and structural modes
void test_stick_slip(ExplainState& st);         // trains of slips while an axis creeps
void fit_reference_channel(ExplainState& st);   // machine effects on reference − set-point, beside both
void breakaway_at_reversals(ExplainState& st);  // a reversal's lag within the stick-slip's sawtooth
void separate_timing(ExplainState& st);         // the sensors' dynamics against the DAQ delay
void report_earth_rate(ExplainState& st);       // site.coriolis from the site
void test_standstill_bias(ExplainState& st);    // bias steps, drift, temperature at the standstills
void test_damping_band(ExplainState& st);       // damping growing with |a|, in the shared vibration
void compare_accelerations(
    ExplainState& st);  // runs nothing holds: mounting angle, scale, lag and bias in acceleration
// A sensor mounted otherwise than run.toml says (flip, swap, mirror): explain_run then
// explains the run with the mounting that fits, the finding first.
std::optional<MountingFit> wrong_mounting(const ExplainState& st);
ExplainedEffect mounting_effect(const MountingFit& m);
void apply_physical_bounds(ExplainState& st);  // a size no sensor or machine can have is not that effect
void report_unexplained(ExplainState& st);     // a residual beyond the noise that no effect explains
void extend_and_measure(ExplainState& st);     // take the sensor side into the model, measure the gain
void rank(ExplainState& st);                   // significant first, then by importance

}  // namespace eical::dsp::model::stage
