#include "sim/regimes/regimes.hpp"

#include "dsp/core/error.hpp"
#include "sim/sensor/axes_map.hpp"

#include <algorithm>
#include <cmath>

namespace eical::sim {

void set_sensors_present(Scenario& scenario, const std::string& which) {
  if (which != "both" && which != "head" && which != "table")
    throw dsp::InputError("sensors: '" + which + "' is not both, head or table");
  scenario.meta.sensor_present[0] = which != "head";
  scenario.meta.sensor_present[1] = which != "table";
}

void set_daq_rate(Scenario& scenario, double fs_hz) {
  if (!(fs_hz >= 100.0 && fs_hz <= 51200.0)) throw dsp::InputError("fs: the DAQ rate must be 100 Hz .. 51.2 kHz");
  scenario.meta.acquisition.fs_hz = fs_hz;
  scenario.oversample = std::max(2, static_cast<int>(std::ceil(1e5 / fs_hz - 1e-9)));
}

void apply_mems(Scenario& scenario, const MemsChip& chip, double fs_hz, const Eigen::Vector3d& bias_g) {
  const double fs = fs_hz > 0.0 ? fs_hz : chip.fs_hz;
  if (!(fs >= 100.0 && fs <= 51200.0)) throw dsp::InputError("MEMS: the output data rate must be 100 Hz .. 51.2 kHz");
  if (chip.bits < 8 || chip.bits > 24 || !(chip.range_g > 0.0) || !(chip.bandwidth_hz > 0.0) ||
      !(chip.noise_ug_per_rthz >= 0.0))
    throw dsp::InputError("MEMS chip '" + chip.name +
                          "': bits 8..24, a positive range and bandwidth and a noise density are needed");
  auto& acq = scenario.meta.acquisition;
  acq.fs_hz = fs;
  acq.adc_bits = chip.bits;
  acq.adc_lsb_volt = chip.lsb_g();  // k1 = 1 V/g: one count is one LSB of the chip
  acq.adc_offset_counts = 0;
  acq.daq_group_delay_samples = 0.0;
  acq.daq_skew_head_samples = 0.0;
  scenario.daq.anti_alias_filter = false;
  scenario.daq.group_delay_samples = 0.0;
  scenario.daq.skew_head_samples = 0.0;
  std::fill(std::begin(scenario.daq.offset_counts), std::end(scenario.daq.offset_counts), 0);
  scenario.daq.noise_nv_per_rthz = 0.0;
  const dsp::SensorSpec spec = mems_sensor_spec(chip, fs);
  for (int s = 0; s < 2; ++s) {
    const Eigen::Matrix3d mounting = scenario.meta.sensors[s].to_machine;
    scenario.meta.sensors[s] = spec;
    scenario.meta.sensors[s].to_machine = mounting;
    SensorTruth& t = scenario.truth[s];
    const Eigen::Matrix3d true_mounting = t.spec.to_machine;
    t.spec = spec;
    t.spec.to_machine = true_mounting;
    t.spec.bias_g = bias_g;
  }
  scenario.oversample = std::clamp(static_cast<int>(std::ceil(20.0 * spec.f0_hz / fs)), 4, 100);
}

void apply_wrong_mounting(Scenario& scenario, int sensor, const std::string& axes_map) {
  if (sensor < 0 || sensor > 1) throw dsp::InputError("wrong mounting: sensor must be table or head");
  const Eigen::Matrix3d m = axes_map_matrix(axes_map, "wrong mounting");
  SensorTruth& t = scenario.truth[sensor];
  t.spec.to_machine = m * scenario.meta.sensors[sensor].to_machine;
  t.axes_map = axes_map;
}

dsp::WorkEnvelope corexy_printer_envelope() {
  dsp::WorkEnvelope e;
  for (auto& t : e.travel_mm) t[0] = -175.0, t[1] = 175.0;
  e.max_feed_mm_min = 30000.0;
  e.max_accel_mm_s2 = 20000.0;
  return e;
}

Scenario sweep_scenario(const nc::KlipperTest& test, const Eigen::Vector3d& direction, std::uint64_t seed) {
  Scenario sc;
  sc.name = "sweep";
  sc.seed = seed;
  sc.description = "Klipper resonance test " + std::to_string(test.freq_start_hz) + " .. " +
                   std::to_string(test.freq_end_hz) + " Hz, no standstill, ideal machine";
  sc.meta.id = "sim-sweep-s" + std::to_string(seed);
  sc.meta.program.kind = dsp::ProgramKind::freeform;
  // The test's peak speed as the program's feed (run.toml needs a positive one).
  double v = 0.0, v_max = 0.0;
  for (const auto& seg : nc::klipper_segments(test)) {
    const double v_end = v + seg.accel_mm_s2 * seg.duration_s;
    v_max = std::max({v_max, std::abs(v), std::abs(v_end)});
    v = v_end;
  }
  sc.meta.program.feed_mm_min = std::max(1.0, std::round(v_max * 60.0));
  sc.meta.reference = dsp::Reference{"ideal", {"x", "y", "z"}};
  // A gantry as Klipper drives it: the head moves x and y, the table z.
  sc.meta.machine.head_axes = {"x", "y"};
  sc.meta.machine.table_axes = {"z"};
  for (int s = 0; s < 2; ++s) sc.truth[s].spec = sc.meta.sensors[s];
  sc.sweep.on = true;
  sc.sweep.test = test;
  sc.sweep.direction = direction;
  sc.meta.envelope = corexy_printer_envelope();
  return sc;
}

}  // namespace eical::sim
