#pragma once
// Realistic regimes of runs measured by other systems (docs/run-format.md, "Runs
// measured by other systems"), as changes to a scenario: one sensor, a digital MEMS chip
// at its own rate, another DAQ rate, a wrong mounting, Klipper's sweep as the program.
// Each writes what eical is told (scenario.meta) and the truth beside it.
#include "sim/scenario.hpp"
#include "sim/sensor/mems_chip.hpp"

#include <cstdint>
#include <string>

namespace eical::sim {

// "both", "head" or "table": the absent triplex's columns are written empty.
void set_sensors_present(Scenario& scenario, const std::string& which);

// Another DAQ rate with the same anti-alias DAQ (up to 51.2 kHz, the NI PCI-4474's
// maximum): the internal grid keeps ≥ 100 kHz (oversample = ⌈100 kHz / fs⌉, at least 2).
void set_daq_rate(Scenario& scenario, double fs_hz);

// Both sensors become the digital MEMS chip (sim/sensor/mems_chip): the data sheet
// (k1 = 1 V/g; the ADC counts are the chip's own LSBs of range/2^(bits−1) g), no DAQ
// anti-alias filter and no group delay, noise and bandwidth from the chip, sampled at
// fs_hz (0: the chip's own rate; the corner where the chip puts it at that rate: ODR/2
// for adxl345 and lis2dw, 260 Hz for the mpu6050, which at 400 Hz lies above Nyquist). The true bias is the data
// sheet's 0 plus `bias_g` (a few mg on a real chip). Oversampling keeps the internal grid ≥ 20× the corner so the
// aliasing is the chip's, not the simulator's.
void apply_mems(Scenario& scenario, const MemsChip& chip, double fs_hz = 0.0,
                const Eigen::Vector3d& bias_g = Eigen::Vector3d::Zero());

// Sensor `sensor` (0 table, 1 head) is truly mounted as `axes_map` (Klipper notation,
// sim/sensor/axes_map) applied to what run.toml states: a sign flip, a swap, a mirror.
// Listed as the effect sensor.misalignment.
void apply_wrong_mounting(Scenario& scenario, int sensor, const std::string& axes_map);

// The work envelope of the printer Klipper's test runs on: a 350 mm CoreXY (travel about
// the test's start), 500 mm/s, 20 m/s² (Klipper's max_accel of such a printer; its test
// reaches 60 mm/s² per Hz at 200 Hz, 12 m/s², beyond a machining centre's 1 g).
dsp::WorkEnvelope corexy_printer_envelope();

// Klipper's resonance test along `direction` as the whole run (no standstill from the
// first sample to the last), program kind "freeform", an ideal reference on x, y, z; a
// gantry's layout (the head moves x and y, the table z); a printer's envelope.
Scenario sweep_scenario(const nc::KlipperTest& test, const Eigen::Vector3d& direction, std::uint64_t seed = 1);

}  // namespace eical::sim
