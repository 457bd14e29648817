#pragma once
// The accuracy campaign of issue 4: a simulated machine whose two sensors deviate from
// their data sheet (scale within 0.5 %, f0 within 10 %, ζ 0.5–0.8, mounting rotated up to
// 5 mrad; plus a bias random walk and a realistic position loop), calibrated on site by
// the identification program alone (never from the truth), then measured on the thesis'
// three programs, each against the simulator's truth:
//   circle R10, 2.5 m/min, 5 revolutions  radius-deviation error, RMS and peak
//   1-D move 50 mm at 6.5 m/min, 5 runs   end-position error and its scatter
//   rectangle 50 mm at 6.5 m/min           corner errors
// The machine carries PSD configuration B (strips at (0, −10) measuring x and (10, 0)
// measuring y); every program is placed so that it crosses them as a real calibration
// program on such a machine would.
//
// Each figure comes with its noise-limited bound: the smallest error the sensors' white
// noise and bias walk permit with the supports that run had (fusion/error_covariance.hpp:
// the smoother's posterior covariance, carried through the evaluation as a quadratic
// form — the centre fit of each revolution, the dwell means, the mean of the repeats).
#include "dsp/identify/sensor_identification.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace eical::tools::accuracy {

struct Options {
  std::uint64_t seed = 1;
  bool calibrate = true;  // false: the data sheet (to show what identification buys)
  bool oracle = false;    // the true sensor parameters (what a perfect identification would give)
};

struct Figure {
  std::string name, unit = "um";
  double measured = 0.0, bound = 0.0, target = 0.0;  // target: the limit
  [[nodiscard]] double ratio() const { return bound > 0.0 ? measured / bound : 0.0; }
  [[nodiscard]] bool within() const { return measured <= target; }
};

struct Report {
  std::uint64_t seed = 0;
  std::vector<std::string> truth;  // the drawn sensor deviations, as text
  dsp::identify::Identification identification;
  bool calibrated = false, oracle = false;
  std::vector<Figure> figures;
  double seconds = 0.0;  // wall time of the campaign
};

Report run(const Options& options);

// The table as printed by bench_accuracy.
std::string table(const Report& report);

}  // namespace eical::tools::accuracy
