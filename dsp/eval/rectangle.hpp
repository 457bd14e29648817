#pragma once
// Rectangle test (exact stop at each corner, G61): corner position errors, and per side
// the straightness about a least-squares reference line (ISO 230-1) and the angle error
// between adjacent sides. With NBS in the pipeline the axis that stands still on a side
// carries no integration drift, which is what makes sides of a rectangle measurable.
#include <Eigen/Core>

#include <vector>

namespace eical::dsp::eval {

struct RectangleSide {
  Eigen::Vector2d from_mm, to_mm;     // commanded
  double straightness_um = 0.0;       // max − min of the normal deviation about the LSQ line
  double direction_error_urad = 0.0;  // measured LSQ line direction − commanded direction
};

struct RectangleResult {
  std::vector<Eigen::Vector2d> corners_mm;        // commanded corners in the order visited
  std::vector<Eigen::Vector2d> corner_errors_um;  // measured − commanded, mean over the stop
  std::vector<RectangleSide> sides;
  std::vector<double> corner_angle_error_urad;  // measured angle between adjacent sides − commanded
};

// Positions in the program plane (mm) on one clock. Corners are the stops of the set-point
// (at least `min_stop_s` at rest). Throws InputError when there are fewer than 3 stops.
RectangleResult evaluate_rectangle(const std::vector<Eigen::Vector2d>& cmd_mm,
                                   const std::vector<Eigen::Vector2d>& meas_mm, double fs_hz, double min_stop_s = 0.02);

}  // namespace eical::dsp::eval
