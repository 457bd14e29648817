#include "dsp/analysis/analyze_run.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp {

std::pair<int, int> plane_axes(const std::string& plane) {
  if (plane == "zx") return {2, 0};
  if (plane == "yz") return {1, 2};
  return {0, 1};
}

namespace {

int axis_index(const std::string& axis) { return axis == "y" ? 1 : axis == "z" ? 2 : 0; }

void evaluate_circle_program(const Run& run, Analysis& a) {
  const Measurement& m = a.measurement;
  const auto [ia, ib] = plane_axes(run.meta.program.plane);
  eval::CircleInput in;
  in.center_mm = {run.meta.program.center_mm[0], run.meta.program.center_mm[1]};
  in.radius_mm = run.meta.program.radius_mm;
  in.direction = run.meta.program.direction;
  in.sample_index = m.sample_index;
  for (const auto& t : m.triggers)
    if (t.code == 102) in.segment_marks.push_back(t.sample_index);
  for (const auto& p : m.pos_mm) in.pos_mm.emplace_back(p[ia], p[ib]);
  try {
    a.circle = eval::evaluate_circle(in);
  } catch (const InputError& e) {
    a.flags.push_back(std::string("circle: ") + e.what());
    a.degraded = true;
    return;
  }
  // The reference instrument (or the simulator's truth) through the same evaluation.
  const bool has_ref = run.channels.ref[ia] && run.channels.ref[ib];
  if (has_ref) {
    eval::CircleInput ref = in;
    ref.pos_mm.clear();
    bool finite = true;
    for (const auto& p : m.ref_mm) {
      ref.pos_mm.emplace_back(p[ia], p[ib]);
      finite &= std::isfinite(p[ia]) && std::isfinite(p[ib]);
    }
    if (finite) {
      try {
        a.circle_reference = eval::evaluate_circle(ref);
        const auto& dm = a.circle->trace.radius_deviation_um;
        const auto& dr = a.circle_reference->trace.radius_deviation_um;
        if (dm.size() == dr.size() && !dm.empty()) {
          double ss = 0.0;
          for (std::size_t i = 0; i < dm.size(); ++i) ss += (dm[i] - dr[i]) * (dm[i] - dr[i]);
          a.circle_accuracy_rms_um = std::sqrt(ss / static_cast<double>(dm.size()));
        }
      } catch (const InputError& e) {
        a.flags.push_back(std::string("circle reference: ") + e.what());
      }
    }
  }
  // Diagnostics over the steady revolutions.
  eval::CirclePass pass;
  pass.direction = in.direction == "cw" ? -1 : +1;
  pass.fs_hz = m.fs_hz;
  const auto first = in.segment_marks.front(), last = in.segment_marks.back();
  for (std::size_t i = 0; i < m.sample_index.size(); ++i)
    if (m.sample_index[i] >= first && m.sample_index[i] < last) {
      pass.cmd_mm.emplace_back(m.cmd_mm[i][ia], m.cmd_mm[i][ib]);
      pass.meas_mm.emplace_back(m.pos_mm[i][ia], m.pos_mm[i][ib]);
    }
  eval::DiagnosticsOptions opt;
  opt.centre_mm = in.center_mm;
  opt.radius_mm = in.radius_mm;
  try {
    a.diagnostics = eval::diagnose_circle({pass}, opt);
  } catch (const InputError& e) {
    a.flags.push_back(std::string("diagnostics: ") + e.what());
  }
}

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
  } catch (const InputError& e) {
    a.flags.push_back(std::string("step: ") + e.what());
    a.degraded = true;
  }
}

void evaluate_positioning_program(const Run& run, Analysis& a) {
  try {
    a.positioning_input = positioning_deviations(a.measurement, run.meta.program);
    a.positioning = eval::evaluate_positioning(*a.positioning_input);
  } catch (const InputError& e) {
    a.flags.push_back(std::string("positioning: ") + e.what());
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
  std::vector<double> up_run(in.targets_mm.size(), NAN), down_run(in.targets_mm.size(), NAN);
  auto flush_if_complete = [&] {
    const auto full = [](const std::vector<double>& v) {
      return std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d); });
    };
    if (full(up_run) && full(down_run)) {
      in.up_um.push_back(up_run);
      in.down_um.push_back(down_run);
      std::fill(up_run.begin(), up_run.end(), NAN);
      std::fill(down_run.begin(), down_run.end(), NAN);
    }
  };
  for (const auto& t : m.triggers) {
    if (t.code != 102) continue;
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

Analysis analyze_run(const Run& run, const AnalysisOptions& options) {
  if (run.frames.empty()) throw InputError("run '" + run.meta.id + "' holds no frames");
  if (!(run.meta.acquisition.fs_hz > 0.0)) throw InputError("run '" + run.meta.id + "': fs_hz must be positive");
  PipelineConfig cfg = pipeline_config(run.meta, run.frames.size());
  cfg.dynamic = options.dynamic;
  cfg.zupt = options.zupt;
  Pipeline pipeline(cfg);
  for (const auto& f : run.frames) pipeline.step(f);
  Analysis a;
  a.measurement = pipeline.finish();
  a.flags = a.measurement.flags;
  a.degraded = a.measurement.degraded;
  if (a.measurement.sample_index.empty()) return a;  // no motion: nothing to evaluate
  const std::string& kind = run.meta.program.kind;
  if (kind == "circle") evaluate_circle_program(run, a);
  else if (kind == "step") evaluate_step_program(run, a);
  else if (kind == "positioning") evaluate_positioning_program(run, a);
  else a.flags.push_back("program kind '" + kind + "': no evaluation in this version");
  return a;
}

}  // namespace eical::dsp
