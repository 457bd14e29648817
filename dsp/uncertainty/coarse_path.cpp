#include "dsp/uncertainty/coarse_path.hpp"

#include <algorithm>

namespace eical::dsp::uncertainty {

CoarsePathProbe::CoarsePathProbe(const CoarseSchedule& coarse, double delay_samples, std::size_t samples, double fs_hz)
    : coarse_(&coarse), delay_(delay_samples), fs_hz_(fs_hz), samples_(samples) {
  const double h = static_cast<double>(coarse.block);
  auto need = [&](double position) {
    const Read r = read_at(position);
    need_.push_back(r.i0);
    if (r.between) need_.push_back(r.i0 + 1);
  };
  need(-delay_);
  need_.push_back(0);  // the temperatures' start
  for (const std::size_t e : coarse.fine_end) {
    const double a = static_cast<double>(e) - delay_;
    need(a), need(a - h), need(a + h);
    need_.push_back(e);
  }
  std::sort(need_.begin(), need_.end());
  need_.erase(std::unique(need_.begin(), need_.end()), need_.end());
  pos_.resize(need_.size(), Eigen::Vector3d::Zero());
  vel_.resize(need_.size(), Eigen::Vector3d::Zero());
  temp_.resize(need_.size(), Eigen::Vector2d::Zero());
}

CoarsePathProbe::Read CoarsePathProbe::read_at(double position) const noexcept {
  Read r;
  if (samples_ == 0 || position <= 0.0) return r;
  const auto i = static_cast<std::size_t>(position);
  if (i + 1 >= samples_) {
    r.i0 = samples_ - 1;
    return r;
  }
  r.i0 = i, r.f = position - static_cast<double>(i), r.between = true;
  return r;
}

void CoarsePathProbe::sample(std::size_t k, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s,
                             const Eigen::Vector2d& temp_c) noexcept {
  while (next_ < need_.size() && need_[next_] < k) ++next_;
  if (next_ >= need_.size() || need_[next_] != k) return;
  pos_[next_] = pos_mm, vel_[next_] = vel_mm_s, temp_[next_] = temp_c;
  ++next_;
}

std::size_t CoarsePathProbe::slot(std::size_t k) const {
  return static_cast<std::size_t>(std::lower_bound(need_.begin(), need_.end(), k) - need_.begin());
}

template <typename V>
V CoarsePathProbe::value(const std::vector<V>& x, const Read& r) const {
  const std::size_t s = slot(r.i0);
  if (!r.between) return x[s];
  return (1.0 - r.f) * x[s] + r.f * x[s + 1];  // as a linear read of the whole trace
}

CoarsePath CoarsePathProbe::path(bool with_temp) const {
  const CoarseSchedule& c = *coarse_;
  const std::size_t nc = c.fine_end.size();
  const double h = static_cast<double>(c.block);
  CoarsePath p;
  p.pos_mm.resize(nc), p.vel_mm_s.resize(nc), p.acc_mm_s2.resize(nc);
  if (with_temp) p.temp_c.resize(nc);
  const Eigen::Vector3d start = value(pos_, read_at(-delay_));
  const Eigen::Vector2d temp0 = temp_[slot(0)];
  for (std::size_t j = 0; j < nc; ++j) {
    const double a = static_cast<double>(c.fine_end[j]) - delay_;
    p.pos_mm[j] = value(pos_, read_at(a)) - start;
    p.vel_mm_s[j] = value(vel_, read_at(a));
    p.acc_mm_s2[j] = (value(vel_, read_at(a + h)) - value(vel_, read_at(a - h))) * (fs_hz_ / (2.0 * h));
    if (with_temp) p.temp_c[j] = temp_[slot(c.fine_end[j])] - temp0;
  }
  return p;
}

CoarsePath coarse_path(const CoarseSchedule& coarse, double delay_samples, double fs_hz,
                       const std::vector<Eigen::Vector3d>& pos_mm, const std::vector<Eigen::Vector3d>& vel_mm_s,
                       const std::vector<Eigen::Vector2d>* temp_c) {
  const std::size_t n = std::min(pos_mm.size(), vel_mm_s.size());
  const bool with_temp = temp_c && temp_c->size() >= n;
  CoarsePathProbe probe(coarse, delay_samples, n, fs_hz);
  for (std::size_t k = 0; k < n; ++k)
    probe.sample(k, pos_mm[k], vel_mm_s[k], with_temp ? (*temp_c)[k] : Eigen::Vector2d::Zero());
  return probe.path(with_temp);
}

}  // namespace eical::dsp::uncertainty
