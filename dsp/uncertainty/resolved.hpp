#pragma once
// When a figure says something: its magnitude exceeds its expanded uncertainty (k = 2).
// A figure that is not resolved is shown as "not resolved" and never turned into
// compensation; `eical comp` and the reports use this one rule.
#include <cmath>

namespace eical::dsp::uncertainty {

[[nodiscard]] inline bool resolved(double value, double u_k2) noexcept {
  return std::isfinite(value) && std::isfinite(u_k2) && std::abs(value) > u_k2;
}

}  // namespace eical::dsp::uncertainty
