#pragma once
// The time derivative of a trace sampled at fs_hz, by central differences; the first and
// last samples (one neighbour only) are 0.
#include <cstddef>

namespace eical::dsp {

// Vec: std::vector<double> or an Eigen vector (size(), operator[]).
template <class Vec>
Vec central_difference(const Vec& x, double fs_hz) {
  Vec d(x.size());  // sized, not copied: every element is written below
  const auto n = static_cast<std::size_t>(x.size());
  if (n == 0) return d;
  d[0] = d[n - 1] = 0.0;
  for (std::size_t k = 1; k + 1 < n; ++k) d[k] = 0.5 * (x[k + 1] - x[k - 1]) * fs_hz;
  return d;
}

}  // namespace eical::dsp
