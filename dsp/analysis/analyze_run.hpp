#pragma once
// One recorded run → everything eical can say about it: the pipeline over all frames,
// then the evaluation its program calls for. Used by `eical analyze`, `eical demo` and
// eicald (which evaluates every measurement it records), so all three agree by
// construction. An evaluation that cannot be done leaves its result empty and says why
// in `flags`; it does not throw.
#include "dsp/analysis/conformance_kind.hpp"
#include "dsp/analysis/setpoint_cache.hpp"
#include "dsp/analysis/verdict_kind.hpp"
#include "dsp/core/flag.hpp"
#include "dsp/core/parallel_for.hpp"
#include "dsp/core/run.hpp"
#include "dsp/core/sensor_model_covariance.hpp"
#include "dsp/eval/circle.hpp"
#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/eval/path_deviation.hpp"
#include "dsp/eval/positioning.hpp"
#include "dsp/eval/rectangle.hpp"
#include "dsp/eval/repeats.hpp"
#include "dsp/eval/step_response.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/uncertainty/error_source.hpp"

#include <cstdint>
#include <functional>
#include <limits>
#include <map>

#include <optional>
#include <string>
#include <vector>

namespace eical::dsp {

struct Analysis;
struct FigureValue;  // figures.hpp
// Figures a caller derives from an analysis beyond its program's own (keys of its own, e.g.
// `eical volumetric`'s standstills): the uncertainty's draws evaluate them on every
// perturbed path too, and their U lands in Analysis::uncertainty_k2 under their keys. The
// draws call it from several threads at once: it must not write shared state.
using MoreFigures = std::function<std::vector<FigureValue>(const Analysis&)>;

struct AnalysisOptions {
  // Independent work side by side: the smoother's axes, the uncertainty's draws (each
  // draw's generator is seeded by its number, the sums taken in draw order). The results
  // do not depend on it; drivers::thread_for() runs it on the machine's cores.
  ParallelFor parallel = sequential_for();
  DynamicComp dynamic = DynamicComp::two_stage;
  bool zupt = true;
  std::optional<bool> nbs;  // unset: on for rectangles (axis-parallel moves), off otherwise
  bool coriolis = false;  // (3-6) Earth rate from [site]; real machines: on (simulated runs have it only when injected)
  bool cupt = true;       // PSD strips as position fixes
  bool keep_raw = false;  // Measurement::raw (identification, explain, the accuracy bound)
  // What the sensors are compensated with beyond run.toml's [sensors.*] (cross terms of a
  // calibration file) and where that model came from: "datasheet", or the calibration's
  // method ("psd", "ref", "explain").
  StaticCalibration calibration[2];
  std::string sensor_model = "datasheet";
  // The uncertainty of every figure (figure_uncertainty.hpp): Monte Carlo over the error
  // field of the measurement, seeded. The sensor model's covariance is the calibration's
  // when one is applied, else the data sheet's tolerances.
  struct Uncertainty {
    bool enabled = true;
    int draws = 100;
    std::uint64_t seed = 1;
    // A screen (eical plan's variants): after `after_draws` draws, when U of the scalar
    // figure `key` already exceeds `above`, the draws end there. The first draws are the
    // same whether the rest follow or not (each is seeded by its number), so a screen that
    // does not stop gives the U of all the draws. Analysis::uncertainty_draws: how many ran.
    struct StopAbove {
      std::string key;
      double above = 0.0;
      int after_draws = 20;
    };
    std::optional<StopAbove> stop_above;
    // The budget (Analysis::uncertainty_budget): each source of the error alone, drawn
    // `budget_draws` times. Costs a few seconds; eical analyze --budget.
    bool budget = false;
    int budget_draws = 40;
  } uncertainty;
  std::optional<dsp::SensorModelCovariance> model_covariance;
  // The caller's figures beside the program's (MoreFigures), each with U from the same draws.
  MoreFigures more_figures;  // empty: the program's figures only
};

// What the program's evaluation may leave out or fix (the uncertainty's draws re-evaluate
// the same program many times on a perturbed path).
struct EvaluationOptions {
  bool reference = true;                  // also evaluate the reference channel
  std::optional<double> cyclic_pitch_mm;  // diagnostics: this pitch instead of the search
  // The per-point traces (plots, CSV, the reference's RMS); the uncertainty's draws read
  // the figures only.
  bool keep_trace = true;
  // What the set-point alone gives, shared by evaluations of paths on one set-point (the
  // uncertainty's draws; see its header for how it is filled and read). Null: none.
  SetPointCache* setpoint = nullptr;
};

struct Analysis {
  Measurement measurement;
  DynamicComp dynamic = DynamicComp::two_stage;  // what the pipeline did
  bool nbs = false, coriolis = false;
  std::string sensor_model = "datasheet";
  std::optional<eval::CircleResult> circle;            // both directions combined when the run has both
  std::optional<eval::CircleResult> circle_reference;  // the same evaluation of the reference channel
  std::optional<double> circle_accuracy_rms_um;        // RMS of (measured − reference) radius deviation
  std::optional<eval::CircleDiagnostics> diagnostics;
  std::optional<eval::StepResult> step;
  std::optional<eval::PositioningInput> positioning_input;  // deviations per run/target/direction
  std::optional<eval::PositioningResult> positioning;
  std::string step_axis;
  std::optional<eval::RectangleResult> rectangle;
  std::optional<eval::PathDeviation> path;  // free form (and the rectangle's contour)
  std::vector<eval::RepeatGroup> repeats;   // segments between M102 marks run more than once, averaged
  ProgramKind program_kind = ProgramKind::circle;
  bool degraded = false;
  std::vector<Flag> flags;  // pipeline quality flags and evaluation failures
  // Expanded uncertainty (k = 2) of each figure by result key (figures.hpp), one value per
  // element of the figure; absent when it could not be estimated (uncertainty_note says why).
  std::map<std::string, std::vector<double>> uncertainty_k2;
  // The noise-limited U (k = 2) of the same figures: the evaluation of the ideal path with
  // only the sensors' white noise, fused by the smoother optimal for it over the run's own
  // supports (figure_uncertainty.hpp). What this test could reach with perfect sensor
  // models: U / bound says how far the measurement is from its physics.
  std::map<std::string, std::vector<double>> noise_bound_k2;
  // With AnalysisOptions::Uncertainty::budget: per source of the error alone, U (k = 2) of
  // every figure (the same 95th percentile of the figure's error over that source's draws).
  std::map<uncertainty::ErrorSource, std::map<std::string, std::vector<double>>> uncertainty_budget;
  // Scalar figures that are not results, by key, with the reason: a value no draw of the
  // error moves (U exactly 0) is a constant of the evaluation (a detection that did not
  // fire), not a size the measurement knows exactly. Rendered as "not evaluated".
  std::map<std::string, std::string> not_evaluated;
  std::string uncertainty_source;  // "datasheet" or the calibration's method
  std::string uncertainty_note;    // how it was estimated, or why not
  int uncertainty_draws = 0;       // the Monte Carlo draws U comes from (0: not estimated)
  // λ of the truth's estimate the draws perturb (figure_uncertainty.hpp): 0 when the
  // measured shape is all noise, 1 when the noise is negligible beside it.
  double uncertainty_shrink = std::numeric_limits<double>::quiet_NaN();
  // quality.verdict (verdict.hpp), and why.
  Verdict verdict = Verdict::ok;
  std::vector<std::string> verdict_reasons;
  // ISO 14253-1 against the user's tolerances (conformance.hpp); empty without tolerances.
  std::optional<ConformanceResult> conformance;
};

// Throws InputError only when the run itself is unusable (no frames, fs ≤ 0). Holds the
// run's trace; runs of any length: analyze_stream() (dsp/stream), equal results.
Analysis analyze_run(const Run& run, const AnalysisOptions& options = {});

// The pipeline configuration of the analysis.
PipelineConfig analysis_config(const RunMeta& meta, std::size_t capacity_samples, const AnalysisOptions& options);

// What analyze_run does after the pipeline: the integration check, the repeats, the
// program's evaluation, the uncertainty (when the pipeline kept its schedule) and the
// verdict (a.measurement set; failures into a.flags).
void evaluate_measurement(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, Analysis& a);

// The program's evaluation of an analysis whose measurement is set (what analyze_run does
// after the pipeline); adds failures to a.flags.
void evaluate_program(const Run& run, Analysis& a, const EvaluationOptions& options = {});

// Deviations at the targets of a positioning program: at each M102 (target reached) the
// mean of measured − set-point over the second half of the dwell, grouped by target and
// approach direction; a run is one pass up and one pass down (ISO 230-2 linear cycle).
eval::PositioningInput positioning_deviations(const Measurement& m, const Program& program);

// Plane axes of a program ("xy" → 0, 1; "zx" → 2, 0; "yz" → 1, 2).
std::pair<int, int> plane_axes(const std::string& plane);

}  // namespace eical::dsp
