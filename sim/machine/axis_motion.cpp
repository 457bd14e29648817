#include "sim/machine/axis_motion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::sim {

AxisMotion::AxisMotion(const MachineErrors& errors, int axis, double step_s, double start_mm)
    : servo_(errors.servo[axis]),
      backlash_mm_(errors.backlash_um[axis] * 1e-3),
      spike_mm_(errors.spike[axis].amp_um * 1e-3),
      spike_tau_s_(errors.spike[axis].tau_ms * 1e-3),
      cyclic_(errors.cyclic[axis]),
      scale_(errors.scale_ppm[axis] * 1e-6),
      ss_(errors.stick_slip[axis]),
      h_(step_s),
      x_mm_(start_mm),
      vx_mm_s_(0.0),
      prev_cmd_mm_(start_mm),
      prev_vel_mm_s_(0.0),
      // The play starts taken up in + (the last approach was in the positive direction).
      slide_mm_(start_mm - backlash_mm_ / 2.0) {
  active_ = servo_.kv_per_s > 0.0 || backlash_mm_ != 0.0 || spike_mm_ != 0.0 || cyclic_.amp_um != 0.0 ||
            scale_ != 0.0 || ss_.amp_um != 0.0;
  if (servo_.kv_per_s > 0.0) exp_kv_h_ = std::exp(-servo_.kv_per_s * h_);
}

double AxisMotion::servo(double cmd_mm, double cmd_vel_mm_s) noexcept {
  if (!(servo_.kv_per_s > 0.0)) return cmd_mm;
  const double kv = servo_.kv_per_s, ff = servo_.feedforward;
  if (servo_.velocity_tau_s <= 0.0) {
    // e = cmd − x obeys e' = (1 − ff) v − Kv e: exact over the step with v at mid-step.
    const double v_mid = 0.5 * (cmd_vel_mm_s + prev_vel_mm_s_);
    const double e = (prev_cmd_mm_ - x_mm_) * exp_kv_h_ + (1.0 - ff) * v_mid * (1.0 - exp_kv_h_) / kv;
    x_mm_ = cmd_mm - e;
  } else {
    // Second-order loop: x' = vx, vx' = (ff v + Kv (cmd − x) − vx)/T; RK4 with the set-point
    // interpolated linearly over the step.
    const double T = servo_.velocity_tau_s;
    auto f = [&](double frac, double x, double vx, double& dx, double& dvx) {
      const double c = prev_cmd_mm_ + frac * (cmd_mm - prev_cmd_mm_);
      const double v = prev_vel_mm_s_ + frac * (cmd_vel_mm_s - prev_vel_mm_s_);
      dx = vx;
      dvx = (ff * v + kv * (c - x) - vx) / T;
    };
    double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
    f(0.0, x_mm_, vx_mm_s_, k1x, k1v);
    f(0.5, x_mm_ + 0.5 * h_ * k1x, vx_mm_s_ + 0.5 * h_ * k1v, k2x, k2v);
    f(0.5, x_mm_ + 0.5 * h_ * k2x, vx_mm_s_ + 0.5 * h_ * k2v, k3x, k3v);
    f(1.0, x_mm_ + h_ * k3x, vx_mm_s_ + h_ * k3v, k4x, k4v);
    x_mm_ += h_ / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    vx_mm_s_ += h_ / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  return x_mm_;
}

double AxisMotion::stick_slip(double cmd_vel_mm_s) noexcept {
  // lag = set-point − slide (signed). Below the creep speed static friction holds the slide
  // (the lag follows the set-point) until |lag| reaches amp; above it the slide breaks free.
  const double amp = ss_.amp_um * 1e-3;
  const bool creeping = std::abs(cmd_vel_mm_s) * 60.0 < ss_.below_mm_min;
  if (ss_slipping_) {
    // The slide breaks free and stops again: its speed u = U (1 − cos 2πt/T)/2 rises and
    // falls back to zero (no velocity step, so no acceleration impulse), covering the lag
    // plus the set-point's progress over the slip, U = 2 (L0 + v T)/T.
    const double T = ss_.slip_ms * 1e-3;
    ss_slip_t_s_ += h_;
    const double t = std::min(ss_slip_t_s_, T);
    const double U = 2.0 * (ss_slip_from_mm_ + ss_slip_v_mm_s_ * T) / T;
    const double covered = U * (t / 2.0 - T * std::sin(2.0 * std::numbers::pi * t / T) / (4.0 * std::numbers::pi));
    ss_lag_mm_ = ss_slip_from_mm_ + ss_slip_v_mm_s_ * t - covered;
    if (ss_slip_t_s_ >= T) ss_slipping_ = false;
  } else if (creeping) {
    ss_lag_mm_ += cmd_vel_mm_s * h_;
    if (std::abs(ss_lag_mm_) >= amp)
      ss_slipping_ = true, ss_slip_from_mm_ = ss_lag_mm_, ss_slip_v_mm_s_ = cmd_vel_mm_s, ss_slip_t_s_ = 0.0;
  } else if (ss_lag_mm_ != 0.0) {
    ss_slipping_ = true, ss_slip_from_mm_ = ss_lag_mm_, ss_slip_v_mm_s_ = cmd_vel_mm_s,
    ss_slip_t_s_ = 0.0;  // fast: breaks free
  }
  return -ss_lag_mm_;
}

double AxisMotion::step(double cmd_mm, double cmd_vel_mm_s) noexcept {
  if (!active_) return 0.0;
  const double motor = servo(cmd_mm, cmd_vel_mm_s);
  prev_cmd_mm_ = cmd_mm, prev_vel_mm_s_ = cmd_vel_mm_s;
  double dev = motor - cmd_mm;
  if (backlash_mm_ != 0.0) {
    // Play operator: the motor drags the slide only at the ends of the play.
    slide_mm_ = std::clamp(slide_mm_, motor - backlash_mm_ / 2.0, motor + backlash_mm_ / 2.0);
    dev += slide_mm_ - motor + backlash_mm_ / 2.0;  // zero while moving in + after the start
  }
  if (spike_mm_ != 0.0) {
    const int d = cmd_vel_mm_s > 1e-9 ? 1 : (cmd_vel_mm_s < -1e-9 ? -1 : 0);
    if (d != 0 && dir_ != 0 && d != dir_) since_reversal_s_ = 0.0;
    if (d != 0) dir_ = d;
    since_reversal_s_ += h_;
    if (since_reversal_s_ < 12.0 * spike_tau_s_) {
      // Friction holds the slide as the set-point reverses: the lag grows from zero like
      // t² (continuous position and velocity), peaks at tau and decays.
      const double u = since_reversal_s_ / spike_tau_s_;
      dev -= dir_ * spike_mm_ * u * u * std::exp(2.0 * (1.0 - u));
    }
  }
  if (ss_.amp_um != 0.0) dev += stick_slip(cmd_vel_mm_s);
  if (scale_ != 0.0) dev += scale_ * cmd_mm;
  if (cyclic_.amp_um != 0.0)
    dev += cyclic_.amp_um * 1e-3 *
           std::sin(2.0 * std::numbers::pi * cmd_mm / cyclic_.pitch_mm + cyclic_.phase_deg * std::numbers::pi / 180.0);
  return dev;
}

}  // namespace eical::sim
