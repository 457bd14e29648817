#include "sim/nc/sampled_set_point.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::sim::nc {

SampledSetPoint::SampledSetPoint(std::vector<Eigen::Vector3d> pos_mm, double rate_hz,
                                 std::vector<TimedTrigger> triggers, double t0_s, double still_mm)
    : p_(std::move(pos_mm)), rate_(rate_hz), t0_(t0_s), triggers_(std::move(triggers)) {
  if (p_.size() < 2) throw dsp::InputError("sampled set-point: need at least 2 positions");
  if (!(rate_hz > 0.0)) throw dsp::InputError("sampled set-point: rate must be positive");
  for (const auto& p : p_)
    if (!p.allFinite()) throw dsp::InputError("sampled set-point: a position is not finite");
  const std::size_t n = p_.size();
  duration_ = t0_ + static_cast<double>(n - 1) / rate_;
  // Natural cubic spline on a uniform grid (h = 1/rate): M[i−1] + 4 M[i] + M[i+1] =
  // 6 (p[i−1] − 2 p[i] + p[i+1]) / h², M[0] = M[n−1] = 0; Thomas algorithm.
  const double h = 1.0 / rate_;
  m_.assign(n, Eigen::Vector3d::Zero());
  if (n > 2) {
    std::vector<double> c(n, 0.0);
    std::vector<Eigen::Vector3d> d(n, Eigen::Vector3d::Zero());
    for (std::size_t i = 1; i + 1 < n; ++i) {
      const Eigen::Vector3d rhs = 6.0 * (p_[i - 1] - 2.0 * p_[i] + p_[i + 1]) / (h * h);
      const double denom = 4.0 - (i > 1 ? c[i - 1] : 0.0);
      c[i] = 1.0 / denom;
      d[i] = (rhs - (i > 1 ? d[i - 1] : Eigen::Vector3d::Zero())) / denom;
    }
    for (std::size_t i = n - 2; i >= 1; --i) {
      m_[i] = d[i] - c[i] * m_[i + 1];
      if (i == 1) break;
    }
  }
  // Moves: runs of samples where the position changes.
  bool moving = false;
  double start = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    const bool step = (p_[k] - p_[k - 1]).norm() > still_mm;
    const double t = t0_ + static_cast<double>(k - 1) / rate_;
    if (step && !moving) moving = true, start = t;
    if (!step && moving) moving = false, spans_.emplace_back(start, t);
  }
  if (moving) spans_.emplace_back(start, duration_);
  std::sort(triggers_.begin(), triggers_.end(),
            [](const TimedTrigger& a, const TimedTrigger& b) { return a.t_s < b.t_s; });
}

MotionState SampledSetPoint::at(double t_s) const {
  MotionState s;
  const double x = (t_s - t0_) * rate_;
  if (x <= 0.0) {
    s.pos_mm = p_.front();
    return s;
  }
  const auto last = p_.size() - 1;
  if (x >= static_cast<double>(last)) {
    s.pos_mm = p_.back();
    return s;
  }
  const auto i = static_cast<std::size_t>(x);
  const double h = 1.0 / rate_, b = x - static_cast<double>(i), a = 1.0 - b;  // weights of i and i+1
  const Eigen::Vector3d &p0 = p_[i], &p1 = p_[i + 1], &m0 = m_[i], &m1 = m_[i + 1];
  s.pos_mm = a * p0 + b * p1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * (h * h / 6.0);
  s.vel_mm_s = (p1 - p0) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * (h / 6.0);
  s.acc_mm_s2 = a * m0 + b * m1;
  return s;
}

}  // namespace eical::sim::nc
