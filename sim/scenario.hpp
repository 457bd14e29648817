#pragma once
// Everything one simulated run depends on. Nominal values (what eical is told: data sheet,
// program) live in `meta`; the true values the data are generated with live beside them,
// so a scenario can make reality differ from the data sheet (and truth.toml says how).
#include "dsp/core/run_meta.hpp"
#include "sim/nc/trajectory.hpp"

#include <cstdint>
#include <string>

namespace eical::sim {

struct SensorTruth {
  dsp::SensorSpec spec;  // true k1, k2, k3, bias, f0, zeta, noise, mounting
  double temp_c = 20.0;  // constant case temperature (v1)
};

struct Scenario {
  std::string name = "baseline";
  std::string description;
  std::uint64_t seed = 1;
  dsp::RunMeta meta;           // nominal metadata written to run.toml; program.gcode may be empty
  SensorTruth truth[2];        // table, head
  double daq_delay_samples_true = 38.8;
  nc::MachineLimits limits;
  int oversample = 10;         // internal rate = oversample · fs (≥ 100 kHz at 10 kHz)
  bool noise = true;           // white sensor noise (quantisation is always on: for a
                               // near-ideal ADC use adc_bits = 32 and a tiny adc_lsb_volt)
};

// The issue-2 demo circle: R = 10 mm, F = 2500 mm/min, 5 repeats ccw in XY, both sensors
// with data-sheet values equal to the truth, noise 0.4 µg/√Hz, 10 kHz.
Scenario circle_scenario(double radius_mm = 10.0, double feed_mm_min = 2500.0, int repeats = 5,
                         const std::string& direction = "ccw", std::uint64_t seed = 1);

// Step test as in the sample runs: x from targets[0] to targets[1] and back, `runs` times.
Scenario step_scenario(double from_mm = 0.0, double to_mm = 50.0, double feed_mm_min = 3250.0, int runs = 2,
                       std::uint64_t seed = 1);

// ISO 230-2 linear cycle on x over `targets_mm` (ascending), `runs` bidirectional runs.
Scenario positioning_scenario(const std::vector<double>& targets_mm, int runs = 5, double feed_mm_min = 2000.0, std::uint64_t seed = 1);

}  // namespace eical::sim
