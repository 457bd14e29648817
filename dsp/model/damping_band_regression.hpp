#pragma once
// Damping that grows with the acceleration amplitude, seen in the vibration both sensors
// share. The PT2 of a sensing element drops (2ζ/ω0)·ȧ; with ζ = ζ0(1 + k|a|/g) (ch. 8.3.1)
// the part that grows with the amplitude is −(2ζ0k/ω0)·(|a|/g)·ȧ. On a constant-speed
// circle its effect on the path is a lag the mounting's rotation takes up; in the band
// where the machine's common vibration lives (tens to hundreds of Hz) it is not: there
// head − table cancels the vibration except where one element's damping differs, and it
// differs in step with that element's own |a| (the motion). The test regresses the band of
// head − table on what a linear difference between the sensors makes of the common
// vibration (any 3×3 map of a and of ȧ: scale, mounting, cross coupling, 2ζ/ω0, a skew)
// and, per element, on |a|/g·ȧ; k follows from the latter's coefficients.
#include "dsp/model/run_residuals.hpp"

#include <array>
#include <string>

namespace eical::dsp::model {

struct DampingBandFinding {
  bool valid = false;  // both sensors, a vibration to probe with, enough samples
  std::string why;     // when not valid
  bool found = false;
  int sensor = -1;                   // 0 table, 1 head: the larger evidence
  double zeta_per_g = 0.0;           // k of ζ0(1 + k|a|/g), the moving elements' weighted mean
  double sigma_zeta_per_g = 0.0;     // its standard error (effective samples of the band)
  std::array<double, 2> bic_drop{};  // per sensor: its three |a|·ȧ terms, effective samples
  double band_lo_hz = 0.0, band_hi_hz = 0.0;
  double kept_fraction = 0.0;    // samples kept (reversals and impulses out)
  double probe_rms_mg = 0.0;     // the table's band RMS: the vibration that probes
  double residual_rms_ug = 0.0;  // head − table in the band after the fit
  std::string evidence;
};

DampingBandFinding damping_band_test(const RunResiduals& run);

}  // namespace eical::dsp::model
