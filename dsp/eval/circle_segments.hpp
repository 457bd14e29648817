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
};

// cmd_mm: commanded position in the plane, one per entry of sample_index (ascending).
// Marks outside the trace are ignored. Throws InputError on mismatched lengths or a
// non-positive arc.
std::vector<CircleSegment> find_circle_segments(const std::vector<Eigen::Vector2d>& cmd_mm,
                                                const std::vector<std::int64_t>& sample_index,
                                                const std::vector<std::int64_t>& marks, const Eigen::Vector2d& center_mm,
                                                double arc_deg);

}  // namespace eical::dsp::eval
