#pragma once
// One machine axis following its set-point: the position loop (Kv with velocity feed-
// forward, optionally through a first-order velocity loop) and the errors of the axis
// itself — backlash (play between motor and slide), the friction spike after a reversal,
// stick-slip at low feed, scale error and cyclic (ball-screw pitch) error. Stepped once
// per internal sample, in order; returns the slide's deviation from the set-point.
#include "sim/scenario.hpp"

namespace eical::sim {

class AxisMotion {
 public:
  AxisMotion(const MachineErrors& errors, int axis, double step_s, double start_mm);

  // Deviation (mm) of the slide from the set-point at this sample.
  double step(double cmd_mm, double cmd_vel_mm_s) noexcept;
  [[nodiscard]] bool active() const noexcept { return active_; }

 private:
  double servo(double cmd_mm, double cmd_vel_mm_s) noexcept;
  double stick_slip(double cmd_vel_mm_s) noexcept;

  AxisServo servo_;
  double backlash_mm_, spike_mm_, spike_tau_s_;
  CyclicError cyclic_;
  double scale_;
  StickSlip ss_;
  double h_;
  bool active_;
  // Position loop state.
  double x_mm_, vx_mm_s_, prev_cmd_mm_, prev_vel_mm_s_;
  double exp_kv_h_ = 0.0;
  // Backlash: slide position within the play.
  double slide_mm_;
  // Reversal spike: last direction and time since the last reversal.
  int dir_ = 0;
  double since_reversal_s_ = 1e9;
  // Stick-slip: signed lag (set-point − slide), and the slip in progress.
  double ss_lag_mm_ = 0.0, ss_slip_from_mm_ = 0.0, ss_slip_v_mm_s_ = 0.0, ss_slip_t_s_ = 0.0;
  bool ss_slipping_ = false;
};

}  // namespace eical::sim
