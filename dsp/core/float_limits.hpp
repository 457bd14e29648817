#pragma once
// Not-a-number and infinity as doubles. The C macros NAN and INFINITY are floats, so each
// use in double arithmetic is a promotion (-Wdouble-promotion under clang).
#include <limits>

namespace eical {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace eical
