#pragma once
// Which stretches of a circular-test recording are evaluated, and in which direction.
// A circle program marks every evaluated revolution or arc with M102 before and after it
// (sim/gcode/generate.hpp). Between two consecutive marks lies either an evaluated sweep
// or something else (the rest and ramps of a direction change in a "both" program). The
// commanded set-point decides: a stretch is kept when its angle about the programmed
// centre moves monotonically and sweeps the programmed arc (±2°); its sign gives the
// direction. The NC set-point is exact, so no measured data enter this decision.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace eical::dsp::eval {

struct CircleSegment {
  std::int64_t begin_index = 0, end_index = 0;  // sample indices of the two M102 marks
  std::string direction;                        // "ccw" or "cw" (seen from the plane normal)
  double sweep_deg = 0.0;                       // commanded, signed (ccw positive)
  std::size_t samples = 0;                      // trace samples in [begin_index, end_index)
};

// The same decision as the trace goes by: fed every trace sample in order (its set-point
// in the plane, and whether an M102 mark falls on it), it closes a stretch at each mark.
// Marks that fall on no trace sample (before the motion or after the trace) start none.
class CircleSegmentFinder {
 public:
  CircleSegmentFinder(const Eigen::Vector2d& center_mm, double arc_deg);  // throws on arc_deg outside (0, 360]
  void add(std::int64_t sample_index, const Eigen::Vector2d& cmd_mm, bool mark);
  [[nodiscard]] const std::vector<CircleSegment>& segments() const noexcept { return out_; }

 private:
  Eigen::Vector2d centre_;
  double arc_deg_;
  bool open_ = false;
  std::int64_t begin_index_ = 0;
  std::size_t samples_ = 0;  // of the open stretch after its first
  double prev_ = 0.0, sweep_ = 0.0, fwd_ = 0.0, back_ = 0.0;
  std::vector<CircleSegment> out_;
};

// cmd_mm: commanded position in the plane, one per entry of sample_index (ascending).
// Marks outside the trace are ignored. Throws InputError on mismatched lengths or a
// non-positive arc.
std::vector<CircleSegment> find_circle_segments(const std::vector<Eigen::Vector2d>& cmd_mm,
                                                const std::vector<std::int64_t>& sample_index,
                                                const std::vector<std::int64_t>& marks_in,
                                                const Eigen::Vector2d& center_mm, double arc_deg);

}  // namespace eical::dsp::eval
