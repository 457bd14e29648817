#pragma once
// The NC set-point as a function of continuous time: what the interpolator makes of a
// G-code program. Position, velocity and acceleration are analytic (no sampling), so the
// sensor model can evaluate them at its internal rate and the DAQ clock at its own.
#include "sim/gcode/program.hpp"
#include "sim/nc/scurve.hpp"
#include "sim/nc/set_point.hpp"

#include <Eigen/Core>

#include <string_view>
#include <vector>

namespace eical::sim::nc {

// One geometric element of a path (line or arc), parameterised by arc length.
struct PathElement {
  bool is_arc = false;
  Eigen::Vector3d from_mm, to_mm;
  // arc: centre, plane axes (a, b, normal), radius, start angle, signed sweep
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  int axis_a = 0, axis_b = 1, axis_n = 2;
  double radius_mm = 0.0, start_rad = 0.0, sweep_rad = 0.0;
  double length_mm = 0.0;

  [[nodiscard]] Eigen::Vector3d position(double s) const;
  [[nodiscard]] Eigen::Vector3d tangent(double s) const;    // dp/ds, unit
  [[nodiscard]] Eigen::Vector3d curvature(double s) const;  // d²p/ds²
  // Position, velocity and acceleration at path position s for path speed v and path
  // acceleration a — one sine and cosine for all three.
  void state(double s, double v, double a, Eigen::Vector3d& pos, Eigen::Vector3d& vel, Eigen::Vector3d& acc) const;
};

// A blended move: elements driven by one feed profile (G64 tangent-continuous chain, or
// a single G61 block).
struct Move {
  double t0_s = 0.0;
  SCurve profile;
  std::vector<PathElement> elements;
  std::vector<double> s_start_mm;  // path position where each element begins
};

class Trajectory final : public SetPoint {
 public:
  Trajectory(std::vector<Move> moves, std::vector<TimedTrigger> triggers, Eigen::Vector3d start_mm, double duration_s);

  [[nodiscard]] MotionState at(double t_s) const override;
  [[nodiscard]] const std::vector<TimedTrigger>& triggers() const override { return triggers_; }
  [[nodiscard]] const std::vector<Move>& moves() const { return moves_; }
  [[nodiscard]] double duration_s() const override { return duration_; }
  [[nodiscard]] std::vector<std::pair<double, double>> move_spans_s() const override;

 private:
  std::vector<Move> moves_;
  std::vector<TimedTrigger> triggers_;
  Eigen::Vector3d start_mm_;
  double duration_;
};

struct MachineLimits {
  double a_max_mm_s2 = 2000.0;   // path acceleration (the sample runs: 2 m/s²)
  double j_max_mm_s3 = 50000.0;  // path jerk (50 m/s³)
  double rapid_mm_min = 10000.0;
  // Per-axis limits (0 = none). A move's path limits are lowered until no axis exceeds
  // its own: for a path direction t, v_path ≤ v_i / |t_i| (arcs: the in-plane axes see
  // the full path value somewhere on the arc).
  double axis_v_mm_min[3] = {0, 0, 0};
  double axis_a_mm_s2[3] = {0, 0, 0};
  double axis_j_mm_s3[3] = {0, 0, 0};
};

// Interpolates a parsed program. The machine rests at `start_mm` at t = 0 (the program
// must have been parsed with the same start).
Trajectory interpolate(const gcode::Program& program, const Eigen::Vector3d& start_mm, const MachineLimits& limits);

// Parses and interpolates G-code text. The machine is assumed to stand where the
// program's first rapid move (G0) goes — a calibration program positions first and then
// rests for the bias window — or at the origin when it starts with a feed move.
Trajectory interpolate_gcode(std::string_view text, std::string_view name, const MachineLimits& limits);

}  // namespace eical::sim::nc
