#include "dsp/pipeline/dynamic_comp.hpp"

#include <numbers>

namespace eical::dsp {

DynamicCoefficients dynamic_coefficients(const SensorSpec& spec, double d, DynamicComp mode) {
  if (mode == DynamicComp::none) return {};
  const double w0 = 2.0 * std::numbers::pi * spec.f0_hz;
  const double zeta = spec.zeta;
  return {d + 2.0 * zeta / w0, d * d / 2.0 + 2.0 * zeta * d / w0 + 1.0 / (w0 * w0)};  // (6-38) with the delay
}

}  // namespace eical::dsp
