#pragma once
// Dynamic compensation of the sensor (PT2, 6-3) and the DAQ group delay d, at the
// position level — the two-stage direct form (6-38):
//   X_kor = X_s + c1·V_s + c2·A_s
// For a PT2 alone c1 = 2ζ/ω0 and c2 = 1/ω0² (exactly invert H(s) = ω0²/(s² + 2ζω0 s + ω0²)).
// The delay multiplies the measured signal by e^{−sd}; inverting both to second order,
//   e^{sd}/H(s) = (1 + sd + s²d²/2 + …)(1 + (2ζ/ω0)s + s²/ω0²)
//               = 1 + (d + 2ζ/ω0)s + (d²/2 + 2ζd/ω0 + 1/ω0²)s² + O(s³),
// so c1 = d + 2ζ/ω0 and c2 = d²/2 + 2ζd/ω0 + 1/ω0². The neglected s³ terms matter only for
// jerk components near the sensor's bandwidth (for the R10 circle: well below 1 nm).
#include "dsp/core/run_meta.hpp"

namespace eical::dsp {

enum class DynamicComp { none, two_stage };

struct DynamicCoefficients {
  double c1_s = 0.0;   // multiplies velocity
  double c2_s2 = 0.0;  // multiplies acceleration
};

DynamicCoefficients dynamic_coefficients(const SensorSpec& spec, double delay_s, DynamicComp mode);

}  // namespace eical::dsp
