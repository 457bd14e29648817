#pragma once
// Dynamic compensation of the sensor (PT2, 6-29) and the DAQ group delay d.
// The measured signal is A_s = e^{−sd} H(s) A_w with H(s) = ω0²/(s² + 2ζω0 s + ω0²).
// Inverting both to second order,
//   e^{sd}/H(s) = (1 + sd + s²d²/2 + …)(1 + (2ζ/ω0)s + s²/ω0²)
//               = 1 + (d + 2ζ/ω0)s + (d²/2 + 2ζd/ω0 + 1/ω0²)s² + O(s³),
// so the true signal is W = S + c1·sS + c2·s²S with c1 = d + 2ζ/ω0, c2 = d²/2 + 2ζd/ω0 + 1/ω0²
// (without delay: 2ζ/ω0 and 1/ω0², exact for a PT2). The neglected s³ terms matter only
// for jerk components near the sensor's bandwidth (the jerk steps of feed ramps: d³/6·Δjerk).
//
// Ch. 6.3.3 applies this correction at one of three levels (Bild 6-15 … 6-18):
//   acceleration level (6-33): A_kor = A_s + c1·Ȧ_s + c2·Ä_s, then integrated twice
//                               (needs jerk and its derivative: noisy before integration);
//   velocity level (6-34):     V_kor = V_s + c1·A_s + c2·Ȧ_s, then integrated once;
//   position level (6-35):     X_kor = X_s + c1·V_s + c2·A_s — with the measured signals
//                               substituted (6-36, 6-37) this is the two-stage form (6-38),
//                               so position_level and two_stage are one variant.
// Continuous-time they are identical; the discrete derivatives are second-order backward
// differences so that the double trapezoid of them reproduces the signal without lag.
#include "dsp/core/run_meta.hpp"

namespace eical::dsp {

enum class DynamicComp { none, acceleration_level, velocity_level, position_level, two_stage = position_level };

struct DynamicCoefficients {
  double c1_s = 0.0;   // multiplies the first derivative (velocity at the position level)
  double c2_s2 = 0.0;  // multiplies the second derivative (acceleration at the position level)
};

DynamicCoefficients dynamic_coefficients(const SensorSpec& spec, double delay_s, DynamicComp mode);

const char* dynamic_comp_name(DynamicComp mode) noexcept;

}  // namespace eical::dsp
