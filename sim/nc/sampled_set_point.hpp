#pragma once
// A set-point another NC reports: positions at a uniform servo rate (LinuxCNC's commanded
// joint positions at 1 kHz, say), made continuous by a natural cubic spline per axis so the
// simulator can evaluate position, velocity and acceleration at its internal rate. A
// trajectory planner's acceleration steps become ramps over one servo period, which is
// what the drives downstream of the servo period deliver anyway.
#include "sim/nc/set_point.hpp"

#include <vector>

namespace eical::sim::nc {

class SampledSetPoint final : public SetPoint {
 public:
  // pos_mm[k] at t = t0_s + k / rate_hz; at least 2 samples. Triggers on the same clock.
  SampledSetPoint(std::vector<Eigen::Vector3d> pos_mm, double rate_hz, std::vector<TimedTrigger> triggers,
                  double t0_s = 0.0, double still_mm = 1e-7);

  [[nodiscard]] MotionState at(double t_s) const override;
  [[nodiscard]] const std::vector<TimedTrigger>& triggers() const override { return triggers_; }
  [[nodiscard]] double duration_s() const override { return duration_; }
  [[nodiscard]] std::vector<std::pair<double, double>> move_spans_s() const override { return spans_; }

 private:
  std::vector<Eigen::Vector3d> p_, m_;  // samples and spline second derivatives (per s²)
  double rate_, t0_, duration_;
  std::vector<TimedTrigger> triggers_;
  std::vector<std::pair<double, double>> spans_;
};

}  // namespace eical::sim::nc
