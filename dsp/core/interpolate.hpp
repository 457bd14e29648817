#pragma once
// Linear interpolation of one column of a trace at a fractional sample position, clamped to
// the trace's ends (NaN for an empty trace: nothing to interpolate, never a read past it).
#include "dsp/core/float_limits.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <vector>

namespace eical::dsp {

inline double interpolate_at(const std::vector<Eigen::Vector3d>& x, double pos, int axis) {
  if (x.empty()) return kNaN;
  if (!(pos > 0.0)) return x.front()[axis];
  // Compared as doubles before the cast: a position beyond size_t is no index.
  if (pos >= static_cast<double>(x.size() - 1)) return x.back()[axis];
  const auto i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return (1.0 - f) * x[i][axis] + f * x[i + 1][axis];
}

}  // namespace eical::dsp
