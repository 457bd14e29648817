#pragma once
// The accelerometer's mechanical dynamics (6-3): H(s) = ω0² / (s² + 2ζω0 s + ω0²),
// discretised exactly for an input held over each step (state-transition matrix from a
// matrix exponential of the augmented system). The simulator feeds the input at the
// middle of each step, which makes the hold second-order accurate in time.
#include <Eigen/Core>

namespace eical::sim {

class Pt2 {
 public:
  Pt2(double f0_hz, double zeta, double step_s);
  // Starts at rest on a constant input (the sensor has settled).
  void settle(double input) noexcept { x_ = Eigen::Vector2d(input, 0.0); }
  double step(double input) noexcept {
    x_ = phi_ * x_ + gamma_ * input;
    return x_[0];
  }
  [[nodiscard]] double output() const noexcept { return x_[0]; }

 private:
  Eigen::Matrix2d phi_;
  Eigen::Vector2d gamma_;
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero();
};

}  // namespace eical::sim
