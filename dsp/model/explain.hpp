#pragma once
// What the simulation gets wrong about recorded runs, named (run-format.md's effects),
// fitted and measured — the thesis' ch. 8.3 as a tool.
//
// Per run: the nominal model's residuals (run_residuals.hpp), every effect the run's
// motion can show as a model extension (effect_catalog.hpp), forward selection by BIC with
// an effective sample count and a held-out guard (effect_selection.hpp) on each channel,
// weighted by the noise each residual carries; then a tolerance guard — an effect counts
// only when its fitted size lies outside the band a data-sheet sensor or a well-kept
// machine shows (background) — and the tests that are no regression: the bias at the
// standstills (steps between moves, ch. 8.3.2), the DAQ delay of the PSD readings against
// the reference, vibration in the sensors' spectra (ch. 8.3.1). Significant effects come
// first, the one that explains most of the residual first.
#include "dsp/core/run.hpp"
#include "dsp/model/run_residuals.hpp"

#include <Eigen/Core>

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace eical::dsp::model {

struct ExplainedEffect {
  std::string name;
  bool significant = false;
  std::string channel;  // "sensor" | "machine" | "total" | "spectrum" | "standstills" | "psd"
  std::string evidence;
  std::map<std::string, double> params;
  double magnitude = 0.0, tolerance = 0.0;
  std::string unit;
  double bic_drop = 0.0, correlation = 0.0;
  double residual_rms_before_um = 0.0, residual_rms_after_um = 0.0;  // fitting samples, this effect alone
  double heldout_rms_before_um = 0.0, heldout_rms_after_um = 0.0;
  double importance_um = 0.0;     // the residual RMS it explains (ranking)
  bool taken_into_model = false;  // a sensor-side extension the pipeline now compensates with
  // σ of `magnitude` where the fit gives one (NaN: none). With it the physical bounds
  // decide whether the data can size the effect at all (`identifiable`).
  double sigma = std::numeric_limits<double>::quiet_NaN();
  // False: the data cannot support a size — the fitted size, or its 2σ interval, reaches
  // beyond what any sensor or machine of the kind can have (apply_physical_bounds). The
  // effect is then reported without a size; `magnitude` is kept for the evidence only.
  bool identifiable = true;
  std::string group;      // the model group it was fitted as (other.residual_like_<group>)
  std::string resembles;  // what its regressor is, in words
};

struct RunExplanation {
  std::string run_id, reference;
  double nominal_residual_rms_um = 0.0, final_residual_rms_um = 0.0;
  double heldout_nominal_rms_um = 0.0, heldout_final_rms_um = 0.0;
  // Why no position was compared (nothing holds the double integral): the residuals above
  // are then not computed (NaN) and the sensors are judged in acceleration.
  std::string position_not_compared;
  std::vector<ExplainedEffect> effects;  // every effect tested, significant first
  // For the report: the residual per channel before and after the accepted extensions.
  struct Trace {
    std::string channel;
    std::vector<double> t_s, before_um, after_um;
    std::vector<int> axis;
  };
  std::vector<Trace> traces;
  // Show: the nominal residual of each moving axis against the candidate regressors
  // (Pearson r over the run): position, velocity, acceleration, |a|·v, jerk, the other
  // axes' acceleration, temperature, time, the other sensor's signal, the direction since
  // the last reversal.
  struct Correlation {
    int axis = 0;
    std::string regressor;
    double r = 0.0;
  };
  std::vector<Correlation> correlations;
  double seconds = 0.0;  // wall time of the explanation: the caller times it (dsp/ reads no clock)
};

struct ExplainOptions {
  double min_bic_drop = 10.0;
  double min_heldout_gain = 0.02;
};

RunExplanation explain_run(const Run& run, const ExplainOptions& options = {});

// Held out across runs: the pipeline's residual on run `to` (another run of the same
// machine) with the nominal model and with what `from`'s explanation took into the model.
struct TransferGain {
  std::string from_run, to_run;
  double before_um = 0.0, after_um = 0.0;
};
TransferGain transfer_gain(const Run& to, const RunExplanation& from);

}  // namespace eical::dsp::model
