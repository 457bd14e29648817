#include "sim/reference/reference_encoder.hpp"

#include <cmath>
#include <numbers>

namespace eical::sim {

double reference_reading_mm(const ReferenceTruth& ref, int axis, double p_mm) noexcept {
  double nm = p_mm * 1e6 * (1.0 + ref.scale_ppm[axis] * 1e-6);
  const double phase = 2.0 * std::numbers::pi * p_mm * 1e3 / ref.signal_period_um;
  for (int h = 0; h < 2; ++h)
    if (ref.interp_nm[axis][h] != 0.0)
      nm +=
          ref.interp_nm[axis][h] * std::sin((h + 1) * phase + ref.interp_phase_deg[axis][h] * std::numbers::pi / 180.0);
  if (ref.resolution_nm > 0.0) nm = std::round(nm / ref.resolution_nm) * ref.resolution_nm;
  return nm * 1e-6;
}

}  // namespace eical::sim
