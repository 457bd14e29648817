#include "sim/nc/trajectory.hpp"

#include "dsp/core/error.hpp"
#include "sim/gcode/parser.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

namespace eical::sim::nc {

Eigen::Vector3d PathElement::position(double s) const {
  if (!is_arc) return length_mm > 0 ? from_mm + (to_mm - from_mm) * (s / length_mm) : from_mm;
  const double u = length_mm > 0 ? s / length_mm : 0.0;
  const double th = start_rad + sweep_rad * u;
  Eigen::Vector3d p;
  p[axis_a] = center_mm[axis_a] + radius_mm * std::cos(th);
  p[axis_b] = center_mm[axis_b] + radius_mm * std::sin(th);
  p[axis_n] = from_mm[axis_n] + (to_mm[axis_n] - from_mm[axis_n]) * u;  // helical part
  return p;
}

Eigen::Vector3d PathElement::tangent(double s) const {
  if (!is_arc) return length_mm > 0 ? Eigen::Vector3d((to_mm - from_mm) / length_mm) : Eigen::Vector3d::Zero();
  const double th = start_rad + sweep_rad * (s / length_mm);
  const double dth = sweep_rad / length_mm;
  Eigen::Vector3d t;
  t[axis_a] = -radius_mm * std::sin(th) * dth;
  t[axis_b] = radius_mm * std::cos(th) * dth;
  t[axis_n] = (to_mm[axis_n] - from_mm[axis_n]) / length_mm;
  return t;
}

Eigen::Vector3d PathElement::curvature(double s) const {
  if (!is_arc) return Eigen::Vector3d::Zero();
  const double th = start_rad + sweep_rad * (s / length_mm);
  const double dth = sweep_rad / length_mm;
  Eigen::Vector3d k = Eigen::Vector3d::Zero();
  k[axis_a] = -radius_mm * std::cos(th) * dth * dth;
  k[axis_b] = -radius_mm * std::sin(th) * dth * dth;
  return k;
}

void PathElement::state(double s, double v, double a, Eigen::Vector3d& pos, Eigen::Vector3d& vel,
                        Eigen::Vector3d& acc) const {
  if (!is_arc) {
    const Eigen::Vector3d t = length_mm > 0 ? Eigen::Vector3d((to_mm - from_mm) / length_mm) : Eigen::Vector3d::Zero();
    pos = from_mm + t * s;
    vel = t * v;
    acc = t * a;
    return;
  }
  const double u = length_mm > 0 ? s / length_mm : 0.0;
  const double th = start_rad + sweep_rad * u, dth = length_mm > 0 ? sweep_rad / length_mm : 0.0;
  const double c = std::cos(th), sn = std::sin(th);
  const double dn = length_mm > 0 ? (to_mm[axis_n] - from_mm[axis_n]) / length_mm : 0.0;
  pos[axis_a] = center_mm[axis_a] + radius_mm * c;
  pos[axis_b] = center_mm[axis_b] + radius_mm * sn;
  pos[axis_n] = from_mm[axis_n] + (to_mm[axis_n] - from_mm[axis_n]) * u;
  // dp/ds and d²p/ds² as in tangent() and curvature().
  const double ta = -radius_mm * sn * dth, tb = radius_mm * c * dth;
  const double ka = -radius_mm * c * dth * dth, kb = -radius_mm * sn * dth * dth;
  vel[axis_a] = ta * v, vel[axis_b] = tb * v, vel[axis_n] = dn * v;
  acc[axis_a] = ta * a + ka * v * v, acc[axis_b] = tb * a + kb * v * v, acc[axis_n] = dn * a;
}

Trajectory::Trajectory(std::vector<Move> moves, std::vector<TimedTrigger> triggers, Eigen::Vector3d start_mm,
                       double duration_s)
    : moves_(std::move(moves)), triggers_(std::move(triggers)), start_mm_(start_mm), duration_(duration_s) {}

std::vector<std::pair<double, double>> Trajectory::move_spans_s() const {
  std::vector<std::pair<double, double>> spans;
  for (const auto& m : moves_) spans.emplace_back(m.t0_s, m.t0_s + m.profile.duration_s());
  return spans;
}

MotionState Trajectory::at(double t_s) const {
  MotionState st;
  // The last move that started at or before t.
  auto it = std::upper_bound(moves_.begin(), moves_.end(), t_s, [](double v, const Move& m) { return v < m.t0_s; });
  if (it == moves_.begin()) {
    st.pos_mm = start_mm_;
    return st;
  }
  const Move& m = *(it - 1);
  const PathState ps = m.profile.at(t_s - m.t0_s);
  const auto k = static_cast<std::size_t>(std::upper_bound(m.s_start_mm.begin(), m.s_start_mm.end(), ps.s) -
                                          m.s_start_mm.begin() - 1);
  const PathElement& e = m.elements[std::min(k, m.elements.size() - 1)];
  const double s = ps.s - m.s_start_mm[std::min(k, m.elements.size() - 1)];
  e.state(s, ps.v, ps.a, st.pos_mm, st.vel_mm_s, st.acc_mm_s2);
  return st;
}

namespace {

int axis_index_normal(gcode::Plane p) { return p == gcode::Plane::xy ? 2 : (p == gcode::Plane::zx ? 1 : 0); }

PathElement element_of(const gcode::Linear& l) {
  PathElement e;
  e.from_mm = l.from_mm;
  e.to_mm = l.to_mm;
  e.length_mm = (l.to_mm - l.from_mm).norm();
  return e;
}

PathElement element_of(const gcode::Arc& a) {
  PathElement e;
  e.is_arc = true;
  e.from_mm = a.from_mm;
  e.to_mm = a.to_mm;
  e.center_mm = a.center_mm;
  // Counter-clockwise order of the plane axes seen from the positive normal.
  switch (a.plane) {
    case gcode::Plane::xy: e.axis_a = 0, e.axis_b = 1; break;
    case gcode::Plane::zx: e.axis_a = 2, e.axis_b = 0; break;
    case gcode::Plane::yz: e.axis_a = 1, e.axis_b = 2; break;
  }
  e.axis_n = axis_index_normal(a.plane);
  const Eigen::Vector3d r0 = a.from_mm - a.center_mm;
  e.radius_mm = std::hypot(r0[e.axis_a], r0[e.axis_b]);
  e.start_rad = std::atan2(r0[e.axis_b], r0[e.axis_a]);
  e.sweep_rad = a.sweep_rad;
  e.length_mm = std::hypot(e.radius_mm * a.sweep_rad, a.to_mm[e.axis_n] - a.from_mm[e.axis_n]);
  return e;
}

// The open chain of blended elements and the triggers waiting for their path position.
struct Chain {
  std::vector<PathElement> elements;
  double feed_mm_s = 0.0;                        // the lowest feed and arc speed limit in the chain
  std::vector<std::pair<double, int>> triggers;  // (path position, code)
  double length_mm = 0.0;
};

// What is timed so far: the moves, the triggers, the time they take.
struct Timeline {
  std::vector<Move> moves;
  std::vector<TimedTrigger> triggers;
  double t_s = 0.0;
};

// The chain's S-curve: per-axis limits, the largest share of the path speed any axis
// takes in the chain, lower the path's.
SCurve chain_profile(const Chain& chain, double length_mm, const MachineLimits& lim) {
  double v_lim = chain.feed_mm_s, a_lim = lim.a_max_mm_s2, j_lim = lim.j_max_mm_s3;
  for (const auto& e : chain.elements)
    for (int i = 0; i < 3; ++i) {
      const double share = e.is_arc && (i == e.axis_a || i == e.axis_b) ? 1.0 : std::abs(e.tangent(0.0)[i]);
      if (share <= 1e-12) continue;
      if (lim.axis_v_mm_min[i] > 0) v_lim = std::min(v_lim, lim.axis_v_mm_min[i] / 60.0 / share);
      if (lim.axis_a_mm_s2[i] > 0) a_lim = std::min(a_lim, lim.axis_a_mm_s2[i] / share);
      if (lim.axis_j_mm_s3[i] > 0) j_lim = std::min(j_lim, lim.axis_j_mm_s3[i] / share);
    }
  return SCurve(length_mm, v_lim, a_lim, j_lim);
}

// The open chain becomes one move after what is timed, its triggers at their path
// positions; the chain is empty after.
void flush(Chain& chain, const MachineLimits& lim, Timeline& out) {
  if (chain.elements.empty()) return;
  Move m;
  m.t0_s = out.t_s;
  double s = 0.0;
  for (const auto& e : chain.elements) {
    m.s_start_mm.push_back(s);
    s += e.length_mm;
  }
  m.elements = chain.elements;
  m.profile = chain_profile(chain, s, lim);
  for (const auto& [pos, code] : chain.triggers) out.triggers.push_back({out.t_s + m.profile.time_at(pos), code});
  out.t_s += m.profile.duration_s();
  out.moves.push_back(std::move(m));
  chain.elements.clear();
  chain.triggers.clear();
  chain.length_mm = 0.0;
}

// A linear or arc block's path element and its feed, mm/s.
PathElement path_element(const gcode::Block& block, const MachineLimits& lim, double& feed_mm_s) {
  if (const auto* l = std::get_if<gcode::Linear>(&block)) {
    feed_mm_s = (l->rapid ? lim.rapid_mm_min : l->feed_mm_min) / 60.0;
    return element_of(*l);
  }
  const auto& a = std::get<gcode::Arc>(block);
  const PathElement e = element_of(a);
  // Centripetal acceleration v²/r must stay within the machine's limit.
  feed_mm_s = std::min(a.feed_mm_min / 60.0, std::sqrt(lim.a_max_mm_s2 * e.radius_mm));
  return e;
}

// Blend into the open chain only in G64 and where the path is tangent-continuous at the
// same feed.
bool blends(const Chain& chain, const PathElement& e, double feed_mm_s, bool exact_stop) {
  const Eigen::Vector3d t_end = chain.elements.back().tangent(chain.elements.back().length_mm).normalized();
  const Eigen::Vector3d t_start = e.tangent(0.0).normalized();
  const bool tangent = t_end.dot(t_start) > std::cos(1e-3);
  return !(exact_stop || !tangent || std::abs(chain.feed_mm_s - feed_mm_s) > 1e-9);
}

}  // namespace

Trajectory interpolate(const gcode::Program& program, const Eigen::Vector3d& start_mm, const MachineLimits& limits) {
  Timeline out;
  Chain chain;
  for (std::size_t i = 0; i < program.blocks.size(); ++i) {
    const auto& block = program.blocks[i];
    if (const auto* d = std::get_if<gcode::Dwell>(&block)) {
      flush(chain, limits, out);
      out.t_s += d->duration_s;
      continue;
    }
    if (const auto* tr = std::get_if<gcode::Trigger>(&block)) {
      if (chain.elements.empty())
        out.triggers.push_back({out.t_s, tr->code});
      else
        chain.triggers.emplace_back(chain.length_mm, tr->code);
      continue;
    }
    double feed_mm_s = 0.0;
    const PathElement e = path_element(block, limits, feed_mm_s);
    if (!(feed_mm_s > 0.0))
      throw dsp::InputError("interpolator: a move without feed (F word missing) at block " + std::to_string(i + 1));
    if (e.length_mm <= 1e-12) continue;  // e.g. the G0 to where the machine already is
    if (!chain.elements.empty() && !blends(chain, e, feed_mm_s, program.exact_stop)) flush(chain, limits, out);
    if (chain.elements.empty()) chain.feed_mm_s = feed_mm_s;
    chain.elements.push_back(e);
    chain.length_mm += e.length_mm;
    if (program.exact_stop) flush(chain, limits, out);
  }
  flush(chain, limits, out);
  std::stable_sort(out.triggers.begin(), out.triggers.end(),
                   [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  return Trajectory(std::move(out.moves), std::move(out.triggers), start_mm, out.t_s);
}

Trajectory interpolate_gcode(std::string_view text, std::string_view name, const MachineLimits& limits) {
  gcode::ParseOptions opt;
  const gcode::Program first = gcode::parse(text, name, opt);
  for (const auto& b : first.blocks) {
    if (const auto* l = std::get_if<gcode::Linear>(&b)) {
      if (l->rapid) opt.start_mm = l->to_mm;
      break;
    }
    if (std::holds_alternative<gcode::Arc>(b)) break;
  }
  return interpolate(gcode::parse(text, name, opt), opt.start_mm, limits);
}

}  // namespace eical::sim::nc
