#include "dsp/supports/standstill_detector.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::supports {

StandstillDetector::StandstillDetector(const StandstillOptions& options, double fs_hz, double delay_samples,
                                       double noise_var_mps2)
    : opt_(options), var_(noise_var_mps2 > 0.0 ? noise_var_mps2 : 1.0), datasheet_var_(var_), fs_hz_(fs_hz) {
  const auto w = static_cast<std::size_t>(std::max(8.0, std::round(options.window_s * fs_hz)));
  ring_.assign(w, 0.0);
  vring_.assign(std::max(w, static_cast<std::size_t>(std::round(options.vibration_window_s * fs_hz))),
                Eigen::Vector3d::Zero());
  gamma_ = 1.0 + options.z * std::sqrt(2.0 / (3.0 * static_cast<double>(w)));
  cmd_needed_ = static_cast<std::int64_t>(w) + static_cast<std::int64_t>(std::ceil(std::max(delay_samples, 0.0)));
}

void StandstillDetector::reset() noexcept {
  std::fill(ring_.begin(), ring_.end(), 0.0);
  head_ = filled_ = since_recompute_ = bad_ = 0;
  std::fill(vring_.begin(), vring_.end(), Eigen::Vector3d::Zero());
  vhead_ = vfilled_ = 0;
  vsum_.setZero(), vsq_.setZero(), wsum_.setZero(), wsq_.setZero();
  sum_ = t_ = 0.0;
  cmd_still_samples_ = 0;
}

StandstillDetector::Decision StandstillDetector::step(const Eigen::Vector3d& accel_mps2,
                                                      const Eigen::Vector3d& vel_mm_s,
                                                      const Eigen::Vector3d& vel_correction_mm_s, double vel_sigma_mm_s,
                                                      bool cmd_valid, bool cmd_moved) noexcept {
  Decision d;
  if (ring_.empty()) return d;
  // A bad sample (−1 in the ring) holds rest off for a whole window.
  const double e = accel_mps2.allFinite() ? accel_mps2.squaredNorm() : -1.0;
  const double old = ring_[head_];
  if (old < 0.0)
    --bad_;
  else
    sum_ -= old;
  if (e < 0.0)
    ++bad_;
  else
    sum_ += e;
  ring_[head_] = e;
  head_ = (head_ + 1) % ring_.size();
  filled_ = std::min(filled_ + 1, ring_.size());
  const Eigen::Vector3d v = vel_mm_s.allFinite() ? vel_mm_s : Eigen::Vector3d::Zero();
  // The velocity W samples ago leaves the short window (the vibration ring is longer).
  const std::size_t vn = vring_.size(), w = ring_.size();
  if (vfilled_ >= w) {
    const Eigen::Vector3d& out = vring_[(vhead_ + vn - w) % vn];
    wsum_ -= out, wsq_ -= out.cwiseAbs2();
  }
  wsum_ += v, wsq_ += v.cwiseAbs2();
  vsum_ += v - vring_[vhead_];
  vsq_ += v.cwiseAbs2() - vring_[vhead_].cwiseAbs2();
  vring_[vhead_] = v;
  vhead_ = (vhead_ + 1) % vring_.size();
  vfilled_ = std::min(vfilled_ + 1, vring_.size());
  if (++since_recompute_ >= 65536) {  // the running sums' rounding, reset now and then
    sum_ = 0.0;
    for (double x : ring_) sum_ += std::max(x, 0.0);
    vsum_.setZero(), vsq_.setZero(), wsum_.setZero(), wsq_.setZero();
    for (const auto& x : vring_) vsum_ += x, vsq_ += x.cwiseAbs2();
    for (std::size_t i = 0; i < std::min(w, vfilled_); ++i) {
      const Eigen::Vector3d& x = vring_[(vhead_ + vn - 1 - i) % vn];
      wsum_ += x, wsq_ += x.cwiseAbs2();
    }
    since_recompute_ = 0;
  }
  cmd_still_samples_ = cmd_moved ? 0 : cmd_still_samples_ + 1;
  if (filled_ < ring_.size() || bad_ > 0) return d;
  t_ = sum_ / (3.0 * static_cast<double>(w) * var_);
  d.quiet = t_ <= gamma_;
  const bool commanded_rest = cmd_valid && cmd_still_samples_ >= cmd_needed_;
  if (!d.quiet && !commanded_rest) return d;
  if (cmd_valid && !commanded_rest) return d;
  {  // a slow mode rings with little acceleration: the velocity's own spread tells
    const double nw = static_cast<double>(std::min(w, vfilled_));
    d.velocity_spread_mm_s = std::sqrt((wsq_ / nw - (wsum_ / nw).cwiseAbs2()).cwiseMax(0.0).maxCoeff());
    const double nv = static_cast<double>(vfilled_);
    const Eigen::Vector3d var = (vsq_ / nv - (vsum_ / nv).cwiseAbs2()).cwiseMax(0.0);
    d.vibration_sigma_mm_s = std::sqrt(var.maxCoeff());
    d.window_mean_mm_s = vsum_ / nv;
    d.window_lag_s = (nv - 1.0) / 2.0 / fs_hz_;
  }
  // Without a set-point only the integrated velocity tells a glide from a standstill (its
  // spread is no excuse there: it includes the ramp into the glide).
  const double v_max = opt_.velocity_floor_mm_s + 4.0 * vel_sigma_mm_s;
  d.rest = cmd_valid || (vel_mm_s - vel_correction_mm_s).cwiseAbs().maxCoeff() <= v_max;
  return d;
}

}  // namespace eical::dsp::supports
