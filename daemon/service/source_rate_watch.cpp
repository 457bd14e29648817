#include "daemon/service/source_rate_watch.hpp"

#include <cmath>

namespace eical::daemon {

double SourceRateWatch::observe(std::int64_t sample_index, std::int64_t t_ns) {
  if (sample_index < 0 || t_ns <= 0) return 0.0;
  if (!window_.empty() && (sample_index < window_.back().second || t_ns < window_.back().first))
    window_.clear();  // a new numbering
  if (window_.empty() || t_ns != window_.back().first) window_.emplace_back(t_ns, sample_index);
  const auto window_ns = static_cast<std::int64_t>(kWindowS * 1e9);
  while (window_.size() > 2 && t_ns - window_[1].first >= window_ns) window_.pop_front();
  const double span_s = static_cast<double>(t_ns - window_.front().first) * 1e-9;
  if (span_s < kWindowS) return 0.0;
  const double ratio = static_cast<double>(sample_index - window_.front().second) / (span_s * fs_hz_);
  const bool off = ratio > 1.0 + kTolerance || (check_slow_ && ratio < 1.0 - kTolerance);
  return off ? ratio : 0.0;
}

}  // namespace eical::daemon
