#pragma once
// The χ² quantile z standard deviations out (Wilson–Hilferty: (χ²/ν)^(1/3) is near normal
// with mean 1 − 2/(9ν) and variance 2/(9ν)); good to a few per cent from ν = 2 on.
#include <cmath>

namespace eical::dsp {

inline double chi2_quantile(double nu, double z) {
  const double c = 1.0 - 2.0 / (9.0 * nu) + z * std::sqrt(2.0 / (9.0 * nu));
  return nu * c * c * c;
}

}  // namespace eical::dsp
