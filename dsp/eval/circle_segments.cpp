#include "dsp/eval/circle_segments.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

std::vector<CircleSegment> find_circle_segments(const std::vector<Eigen::Vector2d>& cmd,
                                                const std::vector<std::int64_t>& idx,
                                                const std::vector<std::int64_t>& marks_in, const Eigen::Vector2d& centre,
                                                double arc_deg) {
  if (cmd.size() != idx.size()) throw InputError("circle segments: set-point and sample indices differ in length");
  if (!(arc_deg > 0.0 && arc_deg <= 360.0)) throw InputError("circle segments: arc_deg must be in (0, 360]");
  std::vector<std::int64_t> marks;
  for (auto m : marks_in)
    if (!idx.empty() && m >= idx.front() && m <= idx.back()) marks.push_back(m);
  std::sort(marks.begin(), marks.end());
  constexpr double tol_deg = 2.0;      // the trigger sits on the nearest sample: far below 2°
  constexpr double back_step_deg = 1e-3;  // a set-point step against the sweep larger than this breaks monotonicity
  std::vector<CircleSegment> out;
  for (std::size_t k = 0; k + 1 < marks.size(); ++k) {
    const auto b = static_cast<std::size_t>(std::lower_bound(idx.begin(), idx.end(), marks[k]) - idx.begin());
    const auto e = static_cast<std::size_t>(std::lower_bound(idx.begin(), idx.end(), marks[k + 1]) - idx.begin());
    if (e <= b + 1 || e >= cmd.size()) continue;
    double sweep = 0.0, fwd = 0.0, back = 0.0;
    double prev = std::atan2(cmd[b].y() - centre.y(), cmd[b].x() - centre.x());
    for (std::size_t i = b + 1; i <= e; ++i) {
      const double a = std::atan2(cmd[i].y() - centre.y(), cmd[i].x() - centre.x());
      double d = a - prev;  // unwrap
      if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
      if (d < -std::numbers::pi) d += 2 * std::numbers::pi;
      sweep += d;
      fwd = std::max(fwd, d), back = std::min(back, d);
      prev = a;
    }
    const double sweep_deg = sweep * 180.0 / std::numbers::pi;
    const double against_deg = (sweep >= 0 ? -back : fwd) * 180.0 / std::numbers::pi;
    if (std::abs(std::abs(sweep_deg) - arc_deg) > tol_deg || against_deg > back_step_deg) continue;
    out.push_back({marks[k], marks[k + 1], sweep_deg >= 0 ? "ccw" : "cw", sweep_deg});
  }
  return out;
}

}  // namespace eical::dsp::eval
