#pragma once
// The time derivative of a trace sampled at fs_hz, by central differences; the first and
// last samples (one neighbour only) are 0.
#include <cstddef>

namespace eical::dsp {

// Vec: std::vector<double> or an Eigen vector (size(), operator[]).
template <class Vec>
Vec central_difference(const Vec& x, double fs_hz) {
  Vec d = x;
  const auto n = static_cast<std::size_t>(x.size());
  for (std::size_t k = 0; k < n; ++k) d[k] = 0.0;
  for (std::size_t k = 1; k + 1 < n; ++k) d[k] = 0.5 * (x[k + 1] - x[k - 1]) * fs_hz;
  return d;
}

}  // namespace eical::dsp
