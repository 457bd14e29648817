#pragma once
// Vibration in the sensors' own signals, against their noise floor (Welch spectra).
// Where the machine stands still the sensors should read their noise alone; during the
// motion, above 25 Hz, the set-point's own acceleration is gone as well. A line or band
// above the floor in both sensors, in phase (coherent) and gone in head − table is common
// vibration: the machine moving as one (ch. 8.3.1; a single sensor would read it as
// motion). Above the floor in head − table it is differential: head and table really move
// against each other.
#include "dsp/model/run_residuals.hpp"

#include <string>
#include <vector>

namespace eical::dsp::model {

struct SpectralLine {
  double freq_hz = 0.0;
  double excess = 0.0;  // power over the floor (ratio)
  double amp_mg = 0.0;  // equivalent sine amplitude over the line's bins
};

struct VibrationFinding {
  bool found = false;
  double rms_mg = 0.0;              // excess acceleration, RMS over the excess bins (worst axis)
  double displacement_um = 0.0;     // what it makes of the position (RMS, Σ a/ω²)
  double coherence = 0.0;           // table vs head, power-weighted over the excess bins
  std::vector<SpectralLine> lines;  // the strongest bins
  std::string evidence;
};

struct VibrationTests {
  VibrationFinding common, differential;
  double floor_ug_per_rthz = 0.0;  // the noise floor assumed (data sheet)
  double seconds_used = 0.0;
};

VibrationTests vibration_tests(const RunResiduals& run);

}  // namespace eical::dsp::model
