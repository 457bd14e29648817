#include "sim/machine/vibration.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::sim {

DriveModeResponse::DriveModeResponse(const DriveMode& mode, double step_s) : on_(mode.gain.squaredNorm() > 0.0) {
  const double w = 2.0 * std::numbers::pi * mode.freq_hz;
  gain_over_w2_ = mode.gain / (w * w);
  if (!on_) return;
  for (int i = 0; i < 3; ++i)
    if (mode.gain[i] != 0.0) axis_[i].emplace(mode.freq_hz, mode.zeta, step_s);
}

Eigen::Vector3d DriveModeResponse::step(const Eigen::Vector3d& cmd_acc_mm_s2) noexcept {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    if (axis_[i]) m[i] = axis_[i]->step(gain_over_w2_[i] * 0.5 * (cmd_acc_mm_s2[i] + prev_[i]));  // PT2 with DC gain 1
  prev_ = cmd_acc_mm_s2;
  return m;
}

Biquad Biquad::lowpass(double fc_hz, double fs_hz) {
  const double k = std::tan(std::numbers::pi * fc_hz / fs_hz), q = std::numbers::sqrt2 / 2.0;
  const double norm = 1.0 / (1.0 + k / q + k * k);
  Biquad b;
  b.b0 = k * k * norm, b.b1 = 2.0 * b.b0, b.b2 = b.b0;
  b.a1 = 2.0 * (k * k - 1.0) * norm, b.a2 = (1.0 - k / q + k * k) * norm;
  return b;
}

Biquad Biquad::highpass(double fc_hz, double fs_hz) {
  const double k = std::tan(std::numbers::pi * fc_hz / fs_hz), q = std::numbers::sqrt2 / 2.0;
  const double norm = 1.0 / (1.0 + k / q + k * k);
  Biquad b;
  b.b0 = norm, b.b1 = -2.0 * norm, b.b2 = norm;
  b.a1 = 2.0 * (k * k - 1.0) * norm, b.a2 = (1.0 - k / q + k * k) * norm;
  return b;
}

CommonAcceleration::CommonAcceleration(const CommonVibration& vib, double g_mps2, double step_s, int decimation,
                                       std::uint64_t seed)
    : vib_(vib), g_(g_mps2), rng_(seed), decimation_(std::max(1, decimation)) {
  for (const auto& tone : vib.tones) {
    const double ph = tone.phase_deg * std::numbers::pi / 180.0, dph = 2.0 * std::numbers::pi * tone.freq_hz * step_s;
    phasor_.push_back({std::cos(ph), std::sin(ph), std::cos(dph), std::sin(dph)});
  }
  broadband_ = vib.broadband_rms_mg.squaredNorm() > 0.0;
  if (!broadband_) return;
  const double fs = 1.0 / (step_s * decimation_);
  // The band's gain for unit white noise, from the cascade's impulse response energy, so
  // that the broadband part has exactly the requested rms.
  Biquad hp = Biquad::highpass(vib.band_hz[0], fs), lp = Biquad::lowpass(vib.band_hz[1], fs);
  double energy = 0.0;
  const auto n = static_cast<std::size_t>(20.0 * fs / vib.band_hz[0]);
  for (std::size_t k = 0; k < n; ++k) {
    const double y = lp.step(hp.step(k == 0 ? 1.0 : 0.0));
    energy += y * y;
  }
  for (int i = 0; i < 3; ++i) {
    hp_[i] = Biquad::highpass(vib.band_hz[0], fs);
    lp_[i] = Biquad::lowpass(vib.band_hz[1], fs);
    broadband_scale_[i] = vib.broadband_rms_mg[i] * 1e-3 * g_mps2 / std::sqrt(energy);
  }
}

Eigen::Vector3d CommonAcceleration::step() noexcept {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  const bool renormalise = ++steps_ % 4096 == 0;
  for (std::size_t k = 0; k < phasor_.size(); ++k) {
    auto& [c, s, dc, ds] = phasor_[k];
    a += vib_.tones[k].amp_mg * 1e-3 * g_ * s;  // sin(2π f t + φ)
    const double c1 = c * dc - s * ds, s1 = s * dc + c * ds;
    const double norm = renormalise ? 1.0 / std::hypot(c1, s1) : 1.0;
    c = c1 * norm, s = s1 * norm;
  }
  if (broadband_) {
    if (phase_ == 0) {
      from_ = to_;
      for (int i = 0; i < 3; ++i) to_[i] = broadband_scale_[i] * lp_[i].step(hp_[i].step(unit_(rng_)));
    }
    a += from_ + (to_ - from_) * (static_cast<double>(phase_) / decimation_);
    phase_ = (phase_ + 1) % decimation_;
  }
  return a;
}

}  // namespace eical::sim
