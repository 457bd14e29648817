#pragma once
// Digital MEMS accelerometers as 3-D printers and small machines carry them (Klipper's
// adxl345, lis2dw and mpu9250/mpu6050 drivers), with their data-sheet figures:
//
// | chip    | ODR    | range, resolution      | noise (data sheet, one-sided) | bandwidth        |
// |---------|--------|------------------------|-------------------------------|------------------|
// | adxl345 | 3200 Hz| ±16 g, 13 bit: 3.9 mg  | 290 µg/√Hz (x, y)             | ODR/2 (1600 Hz)  |
// | lis2dw  | 1600 Hz| ±16 g, 14 bit: 1.95 mg | 90 µg/√Hz (high performance)  | ODR/2 (800 Hz)   |
// | mpu6050 | 1000 Hz| ±16 g, 16 bit: 0.49 mg | 400 µg/√Hz                    | 260 Hz (DLPF off)|
//
// Data sheets give one-sided densities (rms = n·√bandwidth); run-format.md's are
// two-sided (per-sample σ = n·√fs), so n = n_datasheet/√2 for white noise sampled at fs.
// The chip's low-pass is modelled as the sensor's PT2 with f0 = bandwidth and ζ = 0.707,
// and a chip samples its own output (no anti-alias filter): with the corner at or above
// Nyquist, what lies above fs/2 aliases.
#include "dsp/core/run_meta.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace eical::sim {

struct MemsChip {
  std::string name;
  double fs_hz = 0.0;  // output data rate Klipper runs it at
  int bits = 16;       // resolution over ±range_g
  double range_g = 16.0;
  double noise_ug_per_rthz = 0.0;      // two-sided (run-format.md)
  double bandwidth_hz = 0.0;           // internal low-pass corner at fs_hz
  bool bandwidth_follows_odr = false;  // the corner is ODR/2 at any rate (adxl345, lis2dw)
  [[nodiscard]] double lsb_g() const { return 2.0 * range_g / static_cast<double>(1LL << bits); }
  // The corner when the chip runs at `odr_hz`.
  [[nodiscard]] double bandwidth_at(double odr_hz) const { return bandwidth_follows_odr ? 0.5 * odr_hz : bandwidth_hz; }
};

const std::vector<MemsChip>& mems_chips();
// The chip of that name; throws InputError listing the known ones.
const MemsChip& mems_chip(std::string_view name);

// The data sheet eical is told for a chip running at odr_hz (run.toml [sensors.*]):
// k1 = 1 V/g, no k2/k3, no bias, no temperature coefficients, f0 = its corner at that
// rate, ζ = 0.707, its noise density.
dsp::SensorSpec mems_sensor_spec(const MemsChip& chip, double odr_hz);

}  // namespace eical::sim
