#pragma once
// The expanded uncertainty (GUM, k = 2) of every figure of an analysis: Monte Carlo
// propagation (GUM supplement 1) of the measurement's error field
// (uncertainty/error_field.hpp: integration noise and bias walk between the supports as
// measured at rest, the sensor model, the reference points) through the program's own
// evaluation.
//
// Each draw adds one realisation of the error e to the truth's estimate t̂ (decimated to
// about 1 kHz: the error is smooth and the figures do not need more) and evaluates the
// program again; U of a figure is the 95th percentile of |f(t̂ + e) − f(t̂)| over the draws:
// the distribution of the figure's error itself, no rule on top. t̂ shrinks the measured
// path m towards the set-point s by as much of its shape as the error explains,
// t̂ = s + λ (m − s), λ² = 1 − max‖e‖²/‖m − s‖² over 20 draws: figures that are not linear in the path (G =
// max − min, F, H, A, R) are biased by the noise, by as much as the true shape leaves room
// for — most on a flat path (λ = 0: f(e) itself, the bound |f(t + e) − f(t)| ≤ f(e) of a
// range), least on a path whose shape towers over the noise (λ = 1: the plug-in).
//
// The same draws also give each figure's noise bound: the set-point with only the white
// noise measured at rest, fused by the smoother whose model is that noise (the optimal
// one) over the run's own supports — what this test could reach with a perfect sensor
// model (Analysis::noise_bound_k2).
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/uncertainty/coarse_path.hpp"
#include "dsp/uncertainty/error_field.hpp"

#include <atomic>
#include <functional>
#include <optional>

namespace eical::dsp {

// Fills a.uncertainty_k2 (and its source and note) from the pipeline's configuration.
// Leaves it empty with a note when the measurement has no support schedule.
void estimate_uncertainty(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, Analysis& a);

// What the uncertainty reads of the corrected trace, sample by sample: the error field's
// path on its coarse grid and the path the draws perturb (every draw_step()-th sample) —
// a few MB whatever the run's length. estimate_uncertainty() feeds
// it the trace in memory; a streamed analysis (dsp/stream) each sample as it makes it:
// the same numbers either way.
class UncertaintyTrace {
 public:
  // After the pipeline, before the trace: `a` holds the measurement's supports, fs and
  // triggers and the analysis' dynamic compensation; `schedule` is the support schedule the
  // pipeline recorded (one flag per trace sample; zupt_unused as uncertainty::FineSchedule);
  // index_at(k): sample index of trace sample k; samples: the trace's length.
  UncertaintyTrace(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, const Analysis& a,
                   const fusion::SupportSchedule& schedule, std::size_t samples,
                   std::function<std::int64_t(std::size_t)> index_at, const std::vector<bool>* zupt_unused = nullptr);
  UncertaintyTrace(const UncertaintyTrace&) = delete;
  UncertaintyTrace& operator=(const UncertaintyTrace&) = delete;

  // Trace sample k (in order from 0) as evaluated: corrected, on the set-point's time;
  // temp_c: the case temperatures of table and head there (the last finite ones).
  void sample(std::size_t k, std::int64_t sample_index, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s,
              const Eigen::Vector3d& cmd_mm, const Eigen::Vector3d& ref_mm, const Eigen::Vector2d& temp_c);

  // The draws' integration noise (uncertainty::draw_noise()), drawn before finish(): it
  // reads only the coarse schedule, so a streamed analysis draws it beside its second pass
  // (safe beside sample()). Several threads may call it at once: each takes the next draw
  // not taken until none is left. Optional: finish() draws what was not drawn, the same.
  void draw_noise();

  // After the last sample, `a` evaluated at full rate: the draws; fills a.uncertainty_k2,
  // its source and note.
  void finish(const Run& run, Analysis& a);

  [[nodiscard]] std::size_t draw_step() const noexcept { return q_; }

 private:
  uncertainty::ErrorFieldInput in_;
  std::optional<uncertainty::CoarseSchedule> coarse_;
  std::optional<uncertainty::CoarsePathProbe> probe_;         // reads coarse_
  std::vector<std::optional<uncertainty::NoiseDraw>> noise_;  // draw_noise(): the first draws' noise
  std::atomic<std::size_t> next_noise_{0};                    // the next draw draw_noise() takes
  Measurement nominal_;                                       // every q_-th trace sample
  std::size_t samples_ = 0, q_ = 1;
  int draws_ = 100;
  std::optional<AnalysisOptions::Uncertainty::StopAbove> stop_above_;
  int budget_draws_ = 0;  // 0: no budget
  std::uint64_t seed_ = 0;
  MoreFigures more_;  // AnalysisOptions::more_figures
  ParallelFor parallel_;
};

}  // namespace eical::dsp
