// Circular test of a run: find the evaluated revolutions/arcs per direction from the
// set-point, evaluate each direction (full circle: LSQ centre per revolution; partial
// arc: programmed centre), combine both directions for H, and run the diagnostics on
// full circles.
#include "dsp/analysis/program_evaluations.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/index_span.hpp"
#include "dsp/eval/circle_arc.hpp"
#include "dsp/eval/circle_segments.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace eical::dsp::detail {
namespace {

using Ranges = std::vector<std::pair<std::int64_t, std::int64_t>>;

// One evaluation of the channel `pos` (measured or reference) over the segments found;
// `keep_trace` false: the figures only.
std::optional<eval::CircleResult> evaluate_channel(const Program& p, const std::vector<std::int64_t>& idx,
                                                   const std::vector<Eigen::Vector2d>& pos, const Ranges& ccw,
                                                   const Ranges& cw, bool keep_trace) {
  std::optional<eval::CircleResult> out;
  eval::CircleInput in;
  in.center_mm = {p.center_mm[0], p.center_mm[1]};
  in.radius_mm = p.radius_mm;
  in.keep_trace = keep_trace;
  in.sample_index = idx;
  in.pos_mm = pos;
  for (const auto* ranges : {&ccw, &cw}) {
    if (ranges->empty()) continue;
    in.direction = ranges == &ccw ? "ccw" : "cw";
    in.segments = *ranges;
    eval::CircleResult r = p.arc_deg < 360.0 ? eval::evaluate_arc(in, p.arc_deg) : eval::evaluate_circle(in);
    out = out ? eval::combine(*out, r) : std::move(r);
  }
  return out;
}

// The trace in the program's plane: set-point, measured and (when every sample is finite
// and asked for) the reference.
struct PlaneTrace {
  std::vector<Eigen::Vector2d> cmd, pos, ref;
  bool ref_finite = false;
};

PlaneTrace plane_trace(const Run& run, const Measurement& m, const EvaluationOptions& options) {
  const auto [ia, ib] = plane_axes(run.meta.program.plane);
  PlaneTrace t;
  t.ref_finite = options.reference && run.channels.ref[ia] && run.channels.ref[ib];
  t.cmd.reserve(m.sample_index.size()), t.pos.reserve(m.sample_index.size());
  if (t.ref_finite) t.ref.reserve(m.sample_index.size());
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    t.cmd.emplace_back(m.cmd_mm[i][ia], m.cmd_mm[i][ib]);
    t.pos.emplace_back(m.pos_mm[i][ia], m.pos_mm[i][ib]);
    if (t.ref_finite) {
      t.ref.emplace_back(m.ref_mm[i][ia], m.ref_mm[i][ib]);
      t.ref_finite = t.ref.back().allFinite();
    }
  }
  return t;
}

// The evaluated revolutions (arcs) per direction, between the M102 marks; throws when none
// sweeps the programmed arc.
void find_segments(const Program& p, const Measurement& m, const std::vector<Eigen::Vector2d>& cmd, Ranges& ccw,
                   Ranges& cw) {
  std::vector<std::int64_t> marks;
  for (const auto& t : m.triggers)
    if (t.code == trigger::segment_mark) marks.push_back(t.sample_index);
  for (const auto& s :
       eval::find_circle_segments(cmd, m.sample_index, marks, {p.center_mm[0], p.center_mm[1]}, p.arc_deg))
    (s.direction == "ccw" ? ccw : cw).emplace_back(s.begin_index, s.end_index);
  if (ccw.empty() && cw.empty())
    throw InputError("no stretch between two M102 marks sweeps the programmed " + std::to_string(p.arc_deg) +
                     " deg about the programmed centre");
}

// The reference instrument (or the simulator's truth) through the same evaluation, and the
// RMS of the radius deviation's difference.
void evaluate_reference(const Program& p, const Measurement& m, const std::vector<Eigen::Vector2d>& ref,
                        const Ranges& ccw, const Ranges& cw, Analysis& a) {
  try {
    a.circle_reference = evaluate_channel(p, m.sample_index, ref, ccw, cw, true);
    const auto& dm = a.circle->trace.radius_deviation_um;
    const auto& dr = a.circle_reference->trace.radius_deviation_um;
    if (dm.size() == dr.size() && !dm.empty()) {
      double ss = 0.0;
      for (std::size_t i = 0; i < dm.size(); ++i) ss += (dm[i] - dr[i]) * (dm[i] - dr[i]);
      a.circle_accuracy_rms_um = std::sqrt(ss / static_cast<double>(dm.size()));
    }
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::circle_reference, "circle", e.what()});
  }
}

// One pass per direction over its steady revolutions.
std::vector<eval::CirclePass> diagnostic_passes(const Measurement& m, const PlaneTrace& t, const Ranges& ccw,
                                                const Ranges& cw) {
  std::vector<eval::CirclePass> passes;
  for (const auto* ranges : {&ccw, &cw}) {
    if (ranges->empty()) continue;
    eval::CirclePass pass;
    pass.direction = ranges == &ccw ? +1 : -1;
    pass.fs_hz = m.fs_hz;
    // The indices ascend: evaluate_circle() checked them before the diagnostics are asked for.
    const IndexSpan in = index_span(m.sample_index, ranges->front().first, ranges->back().second);
    pass.cmd_mm.assign(t.cmd.begin() + static_cast<std::ptrdiff_t>(in.begin),
                       t.cmd.begin() + static_cast<std::ptrdiff_t>(in.end));
    pass.meas_mm.assign(t.pos.begin() + static_cast<std::ptrdiff_t>(in.begin),
                        t.pos.begin() + static_cast<std::ptrdiff_t>(in.end));
    passes.push_back(std::move(pass));
  }
  return passes;
}

eval::DiagnosticsOptions diagnostics_options(const Program& p, const EvaluationOptions& options) {
  eval::DiagnosticsOptions opt;
  opt.centre_mm = {p.center_mm[0], p.center_mm[1]};
  opt.radius_mm = p.radius_mm;
  opt.feed_mm_min = p.feed_mm_min;
  if (options.cyclic_pitch_mm) opt.cyclic_pitch_mm = options.cyclic_pitch_mm;
  return opt;
}

// The evaluated revolutions per direction: from the set-point cache when it holds them;
// else found, and a cache not yet frozen takes them with the diagnostics' design.
void revolutions(const Program& p, const Measurement& m, const PlaneTrace& t, const EvaluationOptions& options,
                 Ranges& ccw, Ranges& cw) {
  SetPointCache* cache = options.setpoint;
  if (cache && cache->circle) {
    ccw = cache->circle->ccw, cw = cache->circle->cw;
    return;
  }
  find_segments(p, m, t.cmd, ccw, cw);
  if (!cache || cache->frozen) return;
  SetPointCache::Circle c{ccw, cw, nullptr};
  if (p.arc_deg >= 360.0) {
    try {
      c.design = eval::circle_design(diagnostic_passes(m, t, ccw, cw), diagnostics_options(p, options));
    } catch (const InputError&) {  // diagnose() says why, each time
    }
  }
  cache->circle = std::move(c);
}

// The ballbar-class diagnostics of full circles; a flag instead when they cannot be had.
void diagnose(const Program& p, const std::vector<eval::CirclePass>& passes, const EvaluationOptions& options,
              Analysis& a) {
  const eval::DiagnosticsOptions opt = diagnostics_options(p, options);
  const SetPointCache* cache = options.setpoint;
  try {
    a.diagnostics = cache && cache->circle && cache->circle->design
                        ? eval::diagnose_circle(passes, opt, *cache->circle->design)
                        : eval::diagnose_circle(passes, opt);
    for (auto& reason : eval::null_reasons(*a.diagnostics, opt)) a.flags.push_back(std::move(reason));
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::figure_null, "diagnostics", e.what()});
  }
}

}  // namespace

void evaluate_circle_program(const Run& run, Analysis& a, const EvaluationOptions& options) {
  const Measurement& m = a.measurement;
  const Program& p = run.meta.program;
  const PlaneTrace t = plane_trace(run, m, options);
  Ranges ccw, cw;
  try {
    revolutions(p, m, t, options, ccw, cw);
    a.circle = evaluate_channel(p, m.sample_index, t.pos, ccw, cw, options.keep_trace);
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "circle", e.what()});
    a.degraded = true;
    return;
  }
  if (p.direction == "both" && (ccw.empty() || cw.empty()))
    a.flags.push_back(
        {FlagCode::one_direction, "circle",
         std::string("the program runs both directions but only ") + (ccw.empty() ? "cw" : "ccw") + " was found"});
  if (!a.circle->circular_hysteresis_H_um)
    a.flags.push_back({FlagCode::figure_null, "circle.circular_hysteresis_H_um",
                       "ISO 230-4 H needs both directions (this run has " + a.circle->direction + " only)"});
  if (t.ref_finite && !t.ref.empty()) evaluate_reference(p, m, t.ref, ccw, cw, a);
  if (p.arc_deg < 360.0) {
    a.flags.push_back({FlagCode::figure_null, "diagnostics",
                       "the ballbar-class diagnostics need full revolutions (this run is a " +
                           std::to_string(static_cast<int>(std::lround(p.arc_deg))) + " deg partial arc)"});
    return;
  }
  diagnose(p, diagnostic_passes(m, t, ccw, cw), options, a);
}

}  // namespace eical::dsp::detail
