#pragma once
// The median of a sample (upper median for an even count), `empty` for no values.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace eical::dsp {

inline double median(std::vector<double> v, double empty) {
  if (v.empty()) return empty;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace eical::dsp
