#pragma once
// Two parsed G-code programs compared as the machine would run them: the worst distance
// between their paths (each move sampled along its length, arcs about their centres) and
// between their dwells, and the first difference in kind, direction, feed or trigger.
#include "sim/gcode/program.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace eical::test {

struct ProgramDifference {
  double path_um = 0.0;
  double dwell_ms = 0.0;
  std::string mismatch;  // empty: same blocks, same feeds, same triggers
};

namespace detail {

inline Eigen::Vector3d point_on(const sim::gcode::Block& b, double t) {
  if (const auto* l = std::get_if<sim::gcode::Linear>(&b)) return l->from_mm + t * (l->to_mm - l->from_mm);
  const auto& a = std::get<sim::gcode::Arc>(b);
  const int u = a.plane == sim::gcode::Plane::xy ? 0 : a.plane == sim::gcode::Plane::zx ? 2 : 1;
  const int v = a.plane == sim::gcode::Plane::xy ? 1 : a.plane == sim::gcode::Plane::zx ? 0 : 2;
  const int n = 3 - u - v;
  const double r = std::hypot(a.from_mm[u] - a.center_mm[u], a.from_mm[v] - a.center_mm[v]);
  const double ang = std::atan2(a.from_mm[v] - a.center_mm[v], a.from_mm[u] - a.center_mm[u]) + t * a.sweep_rad;
  Eigen::Vector3d p;
  p[u] = a.center_mm[u] + r * std::cos(ang);
  p[v] = a.center_mm[v] + r * std::sin(ang);
  p[n] = a.from_mm[n] + t * (a.to_mm[n] - a.from_mm[n]);
  return p;
}

inline bool same_number(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace detail

inline ProgramDifference compare_programs(const sim::gcode::Program& want, const sim::gcode::Program& got) {
  using namespace sim::gcode;
  ProgramDifference d;
  if (want.blocks.size() != got.blocks.size()) {
    d.mismatch = std::to_string(want.blocks.size()) + " blocks, read back " + std::to_string(got.blocks.size());
    return d;
  }
  for (std::size_t i = 0; i < want.blocks.size() && d.mismatch.empty(); ++i) {
    const Block &w = want.blocks[i], &g = got.blocks[i];
    const std::string at = "block " + std::to_string(i + 1) + " (line " + std::to_string(want.source[i].line) + ")";
    if (w.index() != g.index()) {
      d.mismatch = at + ": another kind of block";
    } else if (const auto* dw = std::get_if<Dwell>(&w)) {
      d.dwell_ms = std::max(d.dwell_ms, 1e3 * std::abs(dw->duration_s - std::get<Dwell>(g).duration_s));
    } else if (const auto* tw = std::get_if<Trigger>(&w)) {
      const auto& tg = std::get<Trigger>(g);
      if (tw->code != tg.code || !detail::same_number(tw->p, tg.p) || !detail::same_number(tw->q, tg.q))
        d.mismatch = at + ": trigger M" + std::to_string(tw->code) + ", read back M" + std::to_string(tg.code);
    } else {
      const auto* lw = std::get_if<Linear>(&w);
      const auto* aw = std::get_if<Arc>(&w);
      const double feed_w = lw ? lw->feed_mm_min : aw->feed_mm_min;
      const double feed_g = lw ? std::get<Linear>(g).feed_mm_min : std::get<Arc>(g).feed_mm_min;
      const bool rapid = lw && lw->rapid;
      if (lw && lw->rapid != std::get<Linear>(g).rapid) d.mismatch = at + ": G0 and G1";
      if (aw && (aw->clockwise != std::get<Arc>(g).clockwise || aw->plane != std::get<Arc>(g).plane))
        d.mismatch = at + ": arc direction or plane";
      if (!rapid && std::abs(feed_w - feed_g) > 1e-9 * feed_w)
        d.mismatch = at + ": feed " + std::to_string(feed_w) + ", read back " + std::to_string(feed_g);
      for (int k = 0; k <= 32; ++k)
        d.path_um = std::max(d.path_um, 1e3 * (detail::point_on(w, k / 32.0) - detail::point_on(g, k / 32.0)).norm());
    }
  }
  return d;
}

}  // namespace eical::test
