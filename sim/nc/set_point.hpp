#pragma once
// What the simulator needs of an NC: the set-point of the relative position as a function
// of continuous time, the M-function triggers, and when the machine moves. eical's own
// interpolator (Trajectory) provides it from G-code; SampledSetPoint from the positions
// another NC (e.g. LinuxCNC) reports at its servo rate.
#include <Eigen/Core>

#include <utility>
#include <vector>

namespace eical::sim::nc {

struct MotionState {
  Eigen::Vector3d pos_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel_mm_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_mm_s2 = Eigen::Vector3d::Zero();
};

struct TimedTrigger {
  double t_s;
  int code;
};

class SetPoint {
 public:
  virtual ~SetPoint() = default;
  [[nodiscard]] virtual MotionState at(double t_s) const = 0;
  [[nodiscard]] virtual const std::vector<TimedTrigger>& triggers() const = 0;
  [[nodiscard]] virtual double duration_s() const = 0;
  // [start, end] of every move (s): where the set-point leaves and reaches rest.
  [[nodiscard]] virtual std::vector<std::pair<double, double>> move_spans_s() const = 0;
};

}  // namespace eical::sim::nc
