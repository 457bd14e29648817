#include "dsp/pipeline/rest_noise.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp {

double RestNoise::relative_u() const noexcept {
  // The sample median of χ²₁ has about 1.7× the relative spread of the mean of squares
  // (asymptotic efficiency 0.35 … 0.4); the density is the square root: half of it.
  return differences > 0 ? 0.5 * 1.7 * std::sqrt(2.0 / static_cast<double>(differences))
                         : std::numeric_limits<double>::infinity();
}

RestNoiseMeter::RestNoiseMeter(double fs_hz, double g_mps2, std::size_t capacity) : g_mps2_(g_mps2) {
  const double fs = fs_hz > 0.0 ? fs_hz : 1.0;
  // At least 4 samples a cluster: a MEMS sensor at a few hundred Hz has τ of some 10 ms.
  m_ = std::max<std::size_t>(4, static_cast<std::size_t>(std::lround(kTauS * fs)));
  dt_s_ = 1.0 / fs;
  tau_s_ = static_cast<double>(m_) * dt_s_;
  for (auto& d : d2_) d.reserve(capacity);
}

void RestNoiseMeter::sample(const Eigen::Vector3d& rel_mps2) noexcept {
  if (!rel_mps2.allFinite()) return gap();
  ++quiet_samples_;
  sum_ += rel_mps2;
  if (++in_cluster_ < m_) return;
  const Eigen::Vector3d mean = sum_ / static_cast<double>(m_);
  if (have_prev_)
    for (int i = 0; i < 3; ++i) {
      auto& d = d2_[static_cast<std::size_t>(i)];
      if (d.size() < d.capacity()) d.push_back((mean[i] - prev_mean_[i]) * (mean[i] - prev_mean_[i]));
    }
  prev_mean_ = mean, have_prev_ = true;
  sum_.setZero(), in_cluster_ = 0;
}

void RestNoiseMeter::gap() noexcept {
  sum_.setZero(), in_cluster_ = 0;
  have_prev_ = false;
}

void RestNoiseMeter::reset() noexcept {
  gap();
  quiet_samples_ = 0;
  for (auto& d : d2_) d.clear();
}

RestNoise RestNoiseMeter::result() const {
  RestNoise r;
  r.tau_s = tau_s_;
  r.quiet_s = static_cast<double>(quiet_samples_) * dt_s_;
  r.differences = std::min({d2_[0].size(), d2_[1].size(), d2_[2].size()});
  if (!r.measured()) return r;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> d = d2_[static_cast<std::size_t>(i)];
    auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    const double avar = *mid / (2.0 * 0.45494);            // median of χ²₁ is 0.45494
    const double density_mps2 = std::sqrt(tau_s_ * avar);  // two-sided: AVAR = n²/τ
    r.density_ug_rthz[i] = density_mps2 / g_mps2_ * 1e6;
  }
  return r;
}

}  // namespace eical::dsp
