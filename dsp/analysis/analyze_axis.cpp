// The programs along one axis: the step response and ISO 230-2 positioning.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/program_evaluations.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace eical::dsp {
namespace {

// The program's axis (run.toml names one of x, y, z; x for anything else, as before).
int program_axis(const std::string& axis) { return std::max(0, axis_index(axis)); }

}  // namespace

namespace detail {

void evaluate_step_program(const Run& run, Analysis& a, const EvaluationOptions&) {
  const Measurement& m = a.measurement;
  const int ax = program_axis(run.meta.program.axis);
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

void evaluate_positioning_program(const Run& run, Analysis& a, const EvaluationOptions&) {
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

}  // namespace detail

eval::PositioningInput positioning_deviations(const Measurement& m, const Program& program) {
  const int ax = program_axis(program.axis);
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

}  // namespace eical::dsp
