#pragma once
// The stages of `eical demo`, the main job: a calibration as a machine builder runs one,
// on a simulated machine. Part one shows the working instrument (identify the sensors on
// site, then a circular test with PSD strips, evaluated with that calibration); part two a
// test beyond it (a large circle without strips), which eical must call not measurable.
#include "drivers/acquisition/pump.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"
#include "sim/scenario.hpp"
#include "tools/plan/predicted_uncertainty.hpp"

#include <cstdint>
#include <filesystem>
#include <string>

namespace eical::tools::demo {

// The circular test the demo runs, both directions: the thesis' R10 F2500 ×5 over
// configuration B unless told otherwise (eical demo --radius --feed --repeats --psd).
struct DemoTest {
  double radius_mm = 10.0, feed_mm_min = 2500.0;
  int repeats = 5;
  int strips = 2;  // sim::psd_ring: 2 along the path is configuration B
  sim::StripFacing facing = sim::StripFacing::along_path;
};

// The machine the demo calibrates: sensors and strips drawn within the data sheet's
// tolerances for `seed`, small machine errors, plus a backlash and a squareness error a
// circular test is meant to find. `program`: the circular test it runs.
struct DemoMachine {
  plan::TestProgram program;
  sim::Scenario circle;          // the test on this machine
  sim::Scenario identification;  // eical gen-nc identify on this machine: same sensors, strips
};
DemoMachine demo_machine(std::uint64_t seed, const DemoTest& test = {});

// Stage 1: the identification run and `eical identify` of it; writes the run and the
// calibration (eical-sensor-cal/1) under `out`.
struct OnSiteIdentification {
  drivers::SensorCalibration calibration;
  std::filesystem::path run_dir, file;
  double seconds = 0.0;
};
OnSiteIdentification identify_on_site(const DemoMachine& m, const std::filesystem::path& out);

// Stage 2: the circular test through the daemon's code path (simulated DAQ → acquisition
// thread → lock-free ring → measurement session M101/M102/M103 → the recording).
struct RecordedTest {
  dsp::Run run;
  std::vector<Eigen::Vector3d> truth_mm;  // the simulator's true relative position, per frame of `run`
  drivers::PumpStats stats;
  std::uint64_t frames_lost = 0;
  double seconds = 0.0;
};
RecordedTest record_through_daemon_path(const sim::Scenario& sc, bool realtime);

// Stage 3: the analysis eicald runs, with the calibration applied.
dsp::Analysis analyze_with(const dsp::Run& run, const drivers::SensorCalibration& cal);

// The block the demo prints for one test: verdict, G ± U, U against the noise bound, the
// error against the simulator's truth (its ideal reference instrument).
// `truth`: the same evaluation of the true path (dsp::figures_on_path), or empty.
std::string headline_text(const dsp::Analysis& a, const std::vector<dsp::FigureValue>& truth);

// Part two: a test the inertial physics cannot resolve (R150 F4000, one revolution, no
// strips, data-sheet sensors), simulated and analysed as any run.
dsp::Analysis beyond_the_instrument(std::uint64_t seed);

}  // namespace eical::tools::demo
