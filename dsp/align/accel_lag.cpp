#include "dsp/align/accel_lag.hpp"

#include "dsp/pipeline/static_comp.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::align {
namespace {

// Block means of `d` samples: a boxcar low-pass and decimation in one. Applied to a signal
// smoothed over about d samples first (below), it keeps every pulse's centroid: a set-point
// interpolated linearly between servo cycles has its acceleration in pulses at the cycles,
// which a plain block mean would move to the block's centre (up to half a block).
std::vector<Eigen::Vector3d> decimate(const std::vector<Eigen::Vector3d>& x, std::size_t d) {
  std::vector<Eigen::Vector3d> out(x.size() / d, Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < out.size(); ++k) {
    for (std::size_t j = 0; j < d; ++j) out[k] += x[k * d + j];
    out[k] /= static_cast<double>(d);
  }
  return out;
}

// Centred moving average over 2h+1 samples (the decimated series' second smoothing stage).
std::vector<Eigen::Vector3d> smooth(const std::vector<Eigen::Vector3d>& x, std::size_t h) {
  std::vector<Eigen::Vector3d> out(x.size(), Eigen::Vector3d::Zero());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t lo = 0, hi = 0;  // window [lo, hi)
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t want_lo = i >= h ? i - h : 0, want_hi = std::min(x.size(), i + h + 1);
    while (hi < want_hi) sum += x[hi++];
    while (lo < want_lo) sum -= x[lo++];
    out[i] = sum / static_cast<double>(hi - lo);
  }
  return out;
}

Eigen::Vector3d at_fraction(const std::vector<Eigen::Vector3d>& x, double pos) {
  const auto k = static_cast<std::ptrdiff_t>(std::floor(pos));
  if (k < 0 || k + 1 >= static_cast<std::ptrdiff_t>(x.size())) return Eigen::Vector3d::Constant(std::nan(""));
  const double u = pos - static_cast<double>(k);
  return x[static_cast<std::size_t>(k)] * (1.0 - u) + x[static_cast<std::size_t>(k) + 1] * u;
}

}  // namespace

std::vector<Eigen::Vector3d> measured_accel_mps2(const Run& run) {
  const auto& m = run.meta;
  const StaticComp comp[2] = {StaticComp(m.sensors[0], m.acquisition, m.site),
                              StaticComp(m.sensors[1], m.acquisition, m.site)};
  const std::size_t n = run.frames.size();
  std::vector<Eigen::Vector3d> raw(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Frame& f = run.frames[i];
    raw[i] = comp[1].apply(&f.accel_counts[3], static_cast<double>(f.temp_c[1])) -
             comp[0].apply(&f.accel_counts[0], static_cast<double>(f.temp_c[0]));
  }
  // Sample i of the sensors shows the motion of time i − delay: read it `delay` later.
  double pt2_s = 0.0;
  for (const auto& s : m.sensors) pt2_s += 0.5 * 2.0 * s.zeta / (2.0 * std::numbers::pi * s.f0_hz);
  const double delay = m.acquisition.daq_group_delay_samples + pt2_s * m.acquisition.fs_hz;
  std::vector<Eigen::Vector3d> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double pos = std::min(static_cast<double>(i) + delay, static_cast<double>(n) - 1.0 - 1e-9);
    const Eigen::Vector3d v = at_fraction(raw, pos);
    out[i] = v.allFinite() ? v : raw[n - 1];
  }
  return out;
}

std::vector<Eigen::Vector3d> setpoint_accel_mps2(const std::vector<Eigen::Vector3d>& pos_mm, double fs_hz) {
  std::vector<Eigen::Vector3d> a(pos_mm.size(), Eigen::Vector3d::Zero());
  const double k = fs_hz * fs_hz * 1e-3;  // mm/sample² → m/s²
  for (std::size_t i = 1; i + 1 < pos_mm.size(); ++i) a[i] = (pos_mm[i + 1] - 2.0 * pos_mm[i] + pos_mm[i - 1]) * k;
  return a;
}

LagEstimate estimate_lag(const std::vector<Eigen::Vector3d>& cmd_mps2, const std::vector<Eigen::Vector3d>& meas_mps2,
                         double fs_hz, const LagOptions& options) {
  LagEstimate r;
  const std::size_t d = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(fs_hz / options.rate_hz)));
  const double rate = fs_hz / static_cast<double>(d);
  const std::size_t h = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(0.002 * rate)));  // ±2 ms
  const std::size_t pre = d / 2;  // ≈ d samples, centred: pulses keep their centroid
  const auto cmd = smooth(decimate(pre > 0 ? smooth(cmd_mps2, pre) : cmd_mps2, d), h);
  auto meas = smooth(decimate(pre > 0 ? smooth(meas_mps2, pre) : meas_mps2, d), h);
  const std::size_t n = std::min(cmd.size(), meas.size());
  if (n < 10) return r;

  double peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) peak = std::max(peak, cmd[i].norm());
  if (!(peak > 0.0)) return r;
  // Motion: the set-point accelerates; dilated by the search range so a lagging
  // measurement still falls inside.
  std::vector<char> moving(n, 0);
  const auto pad =
      static_cast<std::size_t>(std::ceil(std::max(std::abs(options.min_lag_s), std::abs(options.max_lag_s)) * rate));
  for (std::size_t i = 0; i < n; ++i)
    if (cmd[i].norm() > options.moving_fraction * peak)
      for (std::size_t j = i >= pad ? i - pad : 0; j < std::min(n, i + pad + 1); ++j) moving[j] = 1;
  // Gravity and bias: the mean of the measurement over the samples used.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::size_t used = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (moving[i]) mean += meas[i], ++used;
  if (used < 10) return r;
  mean /= static_cast<double>(used);
  for (auto& v : meas) v -= mean;

  const auto lag0 = static_cast<std::ptrdiff_t>(std::floor(options.min_lag_s * rate));
  const auto lag1 = static_cast<std::ptrdiff_t>(std::ceil(options.max_lag_s * rate));
  std::vector<double> corr;
  corr.reserve(static_cast<std::size_t>(lag1 - lag0 + 1));
  for (std::ptrdiff_t L = lag0; L <= lag1; ++L) {
    double cm = 0.0, cc = 0.0, mm = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!moving[i]) continue;
      const std::ptrdiff_t j = static_cast<std::ptrdiff_t>(i) + L;
      if (j < 0 || j >= static_cast<std::ptrdiff_t>(n)) continue;
      const Eigen::Vector3d& m = meas[static_cast<std::size_t>(j)];
      cm += cmd[i].dot(m), cc += cmd[i].squaredNorm(), mm += m.squaredNorm();
    }
    corr.push_back(cc > 0.0 && mm > 0.0 ? cm / std::sqrt(cc * mm) : 0.0);
  }
  const auto best = static_cast<std::size_t>(std::max_element(corr.begin(), corr.end()) - corr.begin());
  double frac = 0.0;
  if (best > 0 && best + 1 < corr.size()) {
    const double a = corr[best - 1], b = corr[best], c = corr[best + 1];
    const double den = a - 2.0 * b + c;
    if (den < 0.0) frac = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
  }
  const double lag_samples = static_cast<double>(lag0 + static_cast<std::ptrdiff_t>(best)) + frac;
  r.correlation = corr[best];
  r.lag_s = lag_samples / rate;
  // An edge of the search range is no peak.
  r.valid = best > 0 && best + 1 < corr.size() && r.correlation > 0.3;

  double ss_cmd = 0.0, ss_res = 0.0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (cmd[i].norm() <= options.moving_fraction * peak) continue;
    const Eigen::Vector3d m = at_fraction(meas, static_cast<double>(i) + lag_samples);
    if (!m.allFinite()) continue;
    ss_cmd += cmd[i].squaredNorm(), ss_res += (m - cmd[i]).squaredNorm(), ++k;
  }
  r.moving_samples = k;
  if (k > 0) {
    r.cmd_rms_mps2 = std::sqrt(ss_cmd / static_cast<double>(k));
    r.residual_rms_mps2 = std::sqrt(ss_res / static_cast<double>(k));
    r.residual_ratio = r.residual_rms_mps2 / r.cmd_rms_mps2;
  }
  return r;
}

}  // namespace eical::dsp::align
