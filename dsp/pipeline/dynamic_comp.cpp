#include "dsp/pipeline/dynamic_comp.hpp"

#include <numbers>

namespace eical::dsp {

DynamicCoefficients dynamic_coefficients(const SensorSpec& spec, double delay_s, DynamicComp mode) {
  if (mode == DynamicComp::none) return {};
  const double w0 = 2.0 * std::numbers::pi * spec.f0_hz;
  const double zeta = spec.zeta;
  return {delay_s + 2.0 * zeta / w0,
          delay_s * delay_s / 2.0 + 2.0 * zeta * delay_s / w0 + 1.0 / (w0 * w0)};  // (6-38) with the delay
}

const char* dynamic_comp_name(DynamicComp mode) noexcept {
  switch (mode) {
    case DynamicComp::none: return "none";
    case DynamicComp::acceleration_level: return "acceleration level (6-33)";
    case DynamicComp::velocity_level: return "velocity level (6-34)";
    case DynamicComp::position_level: return "position level, two-stage (6-38)";
  }
  return "?";
}

}  // namespace eical::dsp
