#include "dsp/analysis/analyze_run.hpp"

#include "dsp/analysis/channel_findings.hpp"
#include "dsp/analysis/figure_uncertainty.hpp"
#include "dsp/analysis/program_evaluations.hpp"
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

namespace {

int axis_index(const std::string& axis) { return axis == "y" ? 1 : axis == "z" ? 2 : 0; }

void evaluate_step_program(const Run& run, Analysis& a) {
  const Measurement& m = a.measurement;
  const int ax = axis_index(run.meta.program.axis);
  a.step_axis = run.meta.program.axis;
  std::vector<double> cmd, meas;
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    cmd.push_back(m.cmd_mm[i][ax]);
    meas.push_back(m.pos_mm[i][ax]);
  }
  try {
    a.step = eval::evaluate_steps(cmd, meas, m.fs_hz);
    // Figures the moves cannot give are null in the result; say why here.
    const auto& mv = a.step->moves;
    if (std::none_of(mv.begin(), mv.end(), [](const eval::StepMove& s) { return s.settled; }))
      a.flags.push_back(
          {FlagCode::figure_null, "step.settling_s", "no move settled into the band before its dwell ended"});
    if (a.step->smallest_step_resolved_um <= 0.0)
      a.flags.push_back(
          {FlagCode::figure_null, "step.smallest_step_resolved_um", "not even the largest step was resolved"});
    bool repeat = false;
    for (std::size_t i = 0; i < mv.size(); ++i)
      for (std::size_t k = i + 1; k < mv.size(); ++k)
        repeat |= std::abs(mv[i].to_mm - mv[k].to_mm) < 1e-6 &&
                  (mv[i].to_mm > mv[i].from_mm) == (mv[k].to_mm > mv[k].from_mm);
    if (!repeat)
      a.flags.push_back(
          {FlagCode::figure_null, "step.scatter_um", "no target was approached twice from the same side"});
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "step", e.what()});
    a.degraded = true;
  }
}

void evaluate_positioning_program(const Run& run, Analysis& a) {
  try {
    a.positioning_input = positioning_deviations(a.measurement, run.meta.program);
    a.positioning = eval::evaluate_positioning(*a.positioning_input);
    // ISO 230-2:2014 clause 4.3.2: five runs per target and direction; fewer are evaluated
    // by the same formulas, but the figures are outside the standard (s from < 5 runs).
    if (a.positioning->runs < eval::kRunsPerTargetIso230_2)
      a.flags.push_back({FlagCode::outside_standard, "positioning",
                         std::to_string(a.positioning->runs) + " runs per target and direction, ISO 230-2 asks for " +
                             std::to_string(eval::kRunsPerTargetIso230_2) +
                             ": evaluated by its formulas, outside the standard"});
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "positioning", e.what()});
    a.degraded = true;
  }
}

}  // namespace

eval::PositioningInput positioning_deviations(const Measurement& m, const Program& program) {
  const int ax = axis_index(program.axis);
  eval::PositioningInput in;
  in.axis = program.axis;
  in.targets_mm = program.targets_mm;
  std::sort(in.targets_mm.begin(), in.targets_mm.end());
  if (in.targets_mm.size() < 2) throw InputError("positioning program without targets_mm");
  // Index of each sample in the trace.
  auto at = [&](std::int64_t idx) -> std::ptrdiff_t {
    const auto it = std::lower_bound(m.sample_index.begin(), m.sample_index.end(), idx);
    return it == m.sample_index.end() ? -1 : it - m.sample_index.begin();
  };
  std::vector<double> up_run(in.targets_mm.size(), kNaN), down_run(in.targets_mm.size(), kNaN);
  auto flush_if_complete = [&] {
    const auto full = [](const std::vector<double>& v) {
      return std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d); });
    };
    if (full(up_run) && full(down_run)) {
      in.up_um.push_back(up_run);
      in.down_um.push_back(down_run);
      std::fill(up_run.begin(), up_run.end(), kNaN);
      std::fill(down_run.begin(), down_run.end(), kNaN);
    }
  };
  for (const auto& t : m.triggers) {
    if (t.code != trigger::segment_mark) continue;
    const auto k = at(t.sample_index);
    if (k < 1) continue;
    const auto ku = static_cast<std::size_t>(k);
    // The dwell lasts until the set-point moves again (1 nm: the trigger sample may sit a
    // fraction of a sample before the exact arrival).
    const double target_here = m.cmd_mm[ku][ax];
    std::size_t end = ku;
    while (end + 1 < m.cmd_mm.size() && std::abs(m.cmd_mm[end + 1][ax] - target_here) < 1e-6) ++end;
    const std::size_t from = ku + (end - ku) / 2;
    if (end <= from) continue;
    double dev = 0.0;
    for (std::size_t i = from; i <= end; ++i) dev += m.pos_mm[i][ax] - m.cmd_mm[i][ax];
    dev = dev / static_cast<double>(end - from + 1) * 1000.0;
    in.read_sample_index.emplace_back(m.sample_index[from], m.sample_index[end]);
    // Approach direction: where the set-point came from.
    std::size_t before = ku;
    while (before > 0 && std::abs(m.cmd_mm[before][ax] - target_here) < 1e-6) --before;
    const bool up = m.cmd_mm[ku][ax] > m.cmd_mm[before][ax];
    const double target = m.cmd_mm[ku][ax];
    std::size_t ti = in.targets_mm.size();
    for (std::size_t i = 0; i < in.targets_mm.size(); ++i)
      if (std::abs(in.targets_mm[i] - target) < 1e-6) ti = i;
    if (ti == in.targets_mm.size()) continue;  // a mark that is not at a target
    (up ? up_run : down_run)[ti] = dev;
    flush_if_complete();
  }
  return in;
}

PipelineConfig analysis_config(const RunMeta& meta, std::size_t capacity_samples, const AnalysisOptions& options) {
  PipelineConfig cfg = pipeline_config(meta, capacity_samples);
  cfg.dynamic = options.dynamic;
  cfg.zupt = options.zupt;
  cfg.nbs = options.nbs.value_or(meta.program.kind == ProgramKind::rectangle);
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
  switch (run.meta.program.kind) {
    case ProgramKind::circle: return detail::evaluate_circle_program(run, a, options);
    case ProgramKind::step: return evaluate_step_program(run, a);
    case ProgramKind::positioning: return evaluate_positioning_program(run, a);
    case ProgramKind::rectangle: return detail::evaluate_rectangle_program(run, a);
    case ProgramKind::freeform: return detail::evaluate_freeform_program(run, a);
    case ProgramKind::identify: break;  // swings across the strips: `eical identify` reads it
  }
  a.flags.push_back({FlagCode::unknown_program, program_kind_name(run.meta.program.kind), {}});
}

}  // namespace eical::dsp
