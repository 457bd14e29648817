#pragma once
// A PSD strip's own nonlinearity: it reads u (1 + nl (2u/L)²) for the spot at u from its
// centre on a strip of length L (|nl| within DatasheetTolerance::psd_nonlinearity; what
// sim/psd draws). The shape nl multiplies, at a reading, is what the identification fits
// and the uncertainty draws.
#include "dsp/core/run_meta.hpp"

#include <algorithm>

namespace eical::dsp::supports {

// u·(2u/L)² in µm for a reading at `position_um` (machine, along the strip's axis) of
// `spec`; a reading beyond the strip's end is its end.
inline double psd_nonlinearity_shape_um(const PsdSpec& spec, double position_um) {
  const int axis = spec.measures == "y" ? 1 : 0;  // a strip measures x or y (PsdDecoder)
  const double half_um = 500.0 * spec.length_mm;
  const double u_um = std::clamp(position_um - spec.center_mm[axis] * 1000.0, -half_um, half_um);
  const double r = u_um / half_um;
  return u_um * r * r;
}

}  // namespace eical::dsp::supports
