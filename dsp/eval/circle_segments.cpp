#include "dsp/eval/circle_segments.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

CircleSegmentFinder::CircleSegmentFinder(const Eigen::Vector2d& center_mm, double arc_deg)
    : centre_(center_mm), arc_deg_(arc_deg) {
  if (!(arc_deg > 0.0 && arc_deg <= 360.0)) throw InputError("circle segments: arc_deg must be in (0, 360]");
}

void CircleSegmentFinder::add(std::int64_t sample_index, const Eigen::Vector2d& cmd_mm, bool mark) {
  constexpr double tol_deg = 2.0;         // the trigger sits on the nearest sample: far below 2°
  constexpr double back_step_deg = 1e-3;  // a set-point step against the sweep larger than this breaks monotonicity
  const double a = std::atan2(cmd_mm.y() - centre_.y(), cmd_mm.x() - centre_.x());
  if (open_) {             // this sample belongs to the open stretch (the one that closes it too)
    double d = a - prev_;  // unwrap
    if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
    if (d < -std::numbers::pi) d += 2 * std::numbers::pi;
    sweep_ += d;
    fwd_ = std::max(fwd_, d), back_ = std::min(back_, d);
    prev_ = a;
    ++samples_;
  }
  if (!mark) return;
  if (open_ && samples_ > 1) {
    const double sweep_deg = sweep_ * 180.0 / std::numbers::pi;
    const double against_deg = (sweep_ >= 0 ? -back_ : fwd_) * 180.0 / std::numbers::pi;
    if (!(std::abs(std::abs(sweep_deg) - arc_deg_) > tol_deg || against_deg > back_step_deg))
      out_.push_back({begin_index_, sample_index, sweep_deg >= 0 ? "ccw" : "cw", sweep_deg, samples_});
  }
  open_ = true;
  begin_index_ = sample_index;
  samples_ = 0;
  prev_ = a, sweep_ = fwd_ = back_ = 0.0;
}

std::vector<CircleSegment> find_circle_segments(const std::vector<Eigen::Vector2d>& cmd_mm,
                                                const std::vector<std::int64_t>& sample_index,
                                                const std::vector<std::int64_t>& marks_in,
                                                const Eigen::Vector2d& center_mm, double arc_deg) {
  if (cmd_mm.size() != sample_index.size())
    throw InputError("circle segments: set-point and sample indices differ in length");
  CircleSegmentFinder finder(center_mm, arc_deg);
  std::vector<std::int64_t> marks = marks_in;
  std::sort(marks.begin(), marks.end());
  marks.erase(std::unique(marks.begin(), marks.end()), marks.end());
  // A mark between two samples (lost frames) counts at the first sample after it.
  std::size_t next = 0;
  for (std::size_t i = 0; i < sample_index.size(); ++i) {
    bool mark = false;
    for (; next < marks.size() && marks[next] <= sample_index[i]; ++next)
      mark = mark || (i > 0 || marks[next] == sample_index[i]);
    finder.add(sample_index[i], cmd_mm[i], mark);
  }
  return finder.segments();
}

}  // namespace eical::dsp::eval
