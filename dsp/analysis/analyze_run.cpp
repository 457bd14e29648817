#include "dsp/analysis/analyze_run.hpp"

#include "dsp/analysis/channel_findings.hpp"
#include "dsp/analysis/figure_uncertainty.hpp"
#include "dsp/analysis/program_descriptor.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/pipeline/integration_support.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::dsp {

std::pair<int, int> plane_axes(const std::string& plane) {
  if (plane == "zx") return {2, 0};
  if (plane == "yz") return {1, 2};
  return {0, 1};
}

PipelineConfig analysis_config(const RunMeta& meta, std::size_t capacity_samples, const AnalysisOptions& options) {
  PipelineConfig cfg = pipeline_config(meta, capacity_samples);
  cfg.dynamic = options.dynamic;
  cfg.zupt = options.zupt;
  cfg.nbs = options.nbs.value_or(program_descriptor(meta.program.kind).nbs_by_default);
  cfg.coriolis = options.coriolis;
  cfg.cupt = options.cupt;
  cfg.keep_raw = options.keep_raw;
  cfg.keep_schedule = options.uncertainty.enabled;
  cfg.parallel = options.parallel;
  if (options.sensor_model != "datasheet") cfg.fusion.scale_uncertainty = 3e-5;  // identified on site
  if (options.model_covariance)  // the timing as the identification knows it
    cfg.fusion.timing_uncertainty_s = dsp::timing_sigma_s(*options.model_covariance, axis_owners(meta.machine));
  cfg.calibration[0] = options.calibration[0], cfg.calibration[1] = options.calibration[1];
  return cfg;
}

Analysis analyze_run(const Run& run, const AnalysisOptions& options) {
  if (run.frames.empty()) throw InputError("run '" + run.meta.id + "' holds no frames");
  if (!(run.meta.acquisition.fs_hz > 0.0)) throw InputError("run '" + run.meta.id + "': fs_hz must be positive");
  // Is each channel a measurement at all? Before millimetres are integrated from it.
  std::vector<health::Finding> findings = health::check_channels(run);
  const PipelineConfig cfg = analysis_config(run.meta, run.frames.size(), options);
  Pipeline pipeline(cfg);
  for (const auto& f : run.frames) pipeline.step(f);
  Analysis a;
  a.dynamic = cfg.dynamic, a.nbs = cfg.nbs, a.coriolis = cfg.coriolis;
  a.sensor_model = options.sensor_model;
  a.program_kind = run.meta.program.kind;
  a.measurement = pipeline.finish();
  a.flags = a.measurement.flags;
  a.degraded = a.measurement.degraded;
  if (judge_channels(run.meta, std::move(findings), a))
    evaluate_measurement(run, cfg, options, a);
  else
    judge(run.meta.program, a);
  return a;
}

void evaluate_measurement(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, Analysis& a) {
  // run-format.md, "No standstill": a double integral with nothing to hold it is no
  // position. Every positional figure is null with this reason (the verdict: not
  // measurable); eical explain compares such runs in acceleration against the set-point.
  const std::string unsupported =
      a.measurement.sample_index.empty() ? std::string() : unsupported_integration(a.measurement);
  if (!unsupported.empty()) {
    a.flags.push_back({FlagCode::position_unsupported, {}, unsupported});
    a.degraded = true;
  } else if (!a.measurement.sample_index.empty()) {  // no motion: nothing to evaluate
    eval::RepeatInput ri;
    ri.sample_index = &a.measurement.sample_index, ri.pos_mm = &a.measurement.pos_mm, ri.cmd_mm = &a.measurement.cmd_mm;
    for (const auto& t : a.measurement.triggers)
      if (t.code == trigger::segment_mark) ri.marks.push_back(t.sample_index);
    ri.fs_hz = a.measurement.fs_hz;
    a.repeats = eval::average_repeats(ri);
    evaluate_program(run, a);
    if (options.uncertainty.enabled) estimate_uncertainty(run, config, options, a);
  }
  judge(run.meta.program, a);
}

void evaluate_program(const Run& run, Analysis& a, const EvaluationOptions& options) {
  a.program_kind = run.meta.program.kind;
  if (const auto evaluate = program_descriptor(run.meta.program.kind).evaluate) return evaluate(run, a, options);
  // The identification's swings across the strips: `eical identify` reads it.
  a.flags.push_back({FlagCode::unknown_program, program_kind_name(run.meta.program.kind), {}});
}

}  // namespace eical::dsp
