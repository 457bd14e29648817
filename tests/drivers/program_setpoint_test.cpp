// The program set-point (M101 P names a program; eical's interpolator reconstructs its
// set-point) on simulated runs whose set-point was removed and whose marks were moved:
// the alignment finds the motion again, and the cross-correlation finds a known lag.
#include "drivers/setpoint/program_setpoint.hpp"
#include "drivers/setpoint/program_catalog.hpp"
#include "dsp/align/accel_lag.hpp"
#include "dsp/core/error.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace eical::drivers {
namespace {

// The simulated circle run, and the same with its set-point removed (as the DAQ records it).
struct Pair {
  dsp::Run truth, daq;
};

Pair circle_without_setpoint(int repeats = 2) {
  Pair p;
  p.truth = sim::simulate(sim::circle_scenario(10.0, 2500.0, repeats));
  p.daq = p.truth;
  for (auto& f : p.daq.frames) {
    for (double& c : f.cmd_mm) c = 0.0;
    f.flags |= dsp::frame_flag::cmd_missing;
  }
  return p;
}

double max_cmd_error_um(const dsp::Run& a, const dsp::Run& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(a.frames[i].cmd_mm[k] - b.frames[i].cmd_mm[k]) * 1000.0);
  return worst;
}

TEST(AccelLag, FindsAKnownDelayOfTheMeasuredMotion) {
  const dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 1));
  std::vector<Eigen::Vector3d> pos;
  for (const auto& f : run.frames) pos.emplace_back(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  const auto cmd = dsp::align::setpoint_accel_mps2(pos, run.fs_hz());
  const auto meas = dsp::align::measured_accel_mps2(run);
  const auto aligned = dsp::align::estimate_lag(cmd, meas, run.fs_hz());
  ASSERT_TRUE(aligned.valid);
  EXPECT_NEAR(aligned.lag_s, 0.0, 5e-5) << "group delay and PT2 delay are removed";
  EXPECT_GT(aligned.correlation, 0.95);
  EXPECT_LT(aligned.residual_ratio, 0.2);
  // The measurement 23.7 ms later than the set-point.
  std::vector<Eigen::Vector3d> late(meas.size());
  const std::size_t shift = 237;
  for (std::size_t i = 0; i < meas.size(); ++i) late[i] = meas[i >= shift ? i - shift : 0];
  const auto found = dsp::align::estimate_lag(cmd, late, run.fs_hz());
  ASSERT_TRUE(found.valid);
  EXPECT_NEAR(found.lag_s, 0.0237, 5e-5);
}

TEST(AccelLag, ASetPointLinearBetweenServoCyclesHasNoLag) {
  const dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 1));
  // The set-point as a 1 kHz servo stream gives it: samples 0.7 ms into every 1 ms, linear
  // in between (its acceleration sits in pulses at the cycles).
  std::vector<Eigen::Vector3d> exact, servo(run.frames.size());
  for (const auto& f : run.frames) exact.emplace_back(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  for (std::size_t i = 0; i < exact.size(); ++i) {
    const std::size_t k0 = i < 7 ? 7 : 7 + (i - 7) / 10 * 10, k1 = std::min(k0 + 10, exact.size() - 1);
    const double u = k1 > k0 ? (static_cast<double>(i) - static_cast<double>(k0)) / static_cast<double>(k1 - k0) : 0.0;
    servo[i] = exact[std::min(k0, exact.size() - 1)] * (1.0 - u) + exact[k1] * u;
  }
  const auto lag = dsp::align::estimate_lag(dsp::align::setpoint_accel_mps2(servo, run.fs_hz()),
                                            dsp::align::measured_accel_mps2(run), run.fs_hz());
  ASSERT_TRUE(lag.valid);
  EXPECT_NEAR(lag.lag_s, 0.0, 5e-5) << "the decimation keeps the pulses where they are";
}

TEST(ProgramSetPoint, ReconstructsTheSetPointFromMovedMarks) {
  Pair p = circle_without_setpoint();
  // The marks as an NC delivers them: M101 12.3 ms late (the DDS trigger), every M102
  // a few ms off (latency jitter).
  std::mt19937 rng(5);
  std::vector<std::pair<std::size_t, int>> marks;
  for (std::size_t i = 0; i < p.daq.frames.size(); ++i)
    if (p.daq.frames[i].trigger != 0) marks.emplace_back(i, p.daq.frames[i].trigger), p.daq.frames[i].trigger = 0;
  for (const auto& [i, code] : marks) {
    const std::size_t late = code == 101 ? 123 : 10 + rng() % 60;
    p.daq.frames[std::min(i + late, p.daq.frames.size() - 1)].trigger = code;
  }
  ProgramSetPointOptions o;
  const auto a = apply_program_setpoint(p.daq, p.truth.meta.program, o);
  EXPECT_TRUE(a.flags.empty()) << (a.flags.empty() ? "" : flag_text(a.flags.front()));
  ASSERT_EQ(a.blocks.size(), 1u) << "a blended circle program is one motion block";
  EXPECT_NEAR(a.blocks[0].marks_offset_s, 0.0123, 1e-9);
  EXPECT_TRUE(a.blocks[0].correlated);
  EXPECT_NEAR(a.blocks[0].offset_s, 0.0, 2e-4) << "the cross-correlation undoes the mark's latency";
  EXPECT_LT(a.residual_ratio, 0.2);
  EXPECT_NEAR(a.lag_s, 0.0, 2e-4);
  // 0.2 ms at 41.7 mm/s: the set-point within 10 µm everywhere.
  EXPECT_LT(max_cmd_error_um(p.daq, p.truth), 10.0);
  for (const auto& f : p.daq.frames) ASSERT_EQ(f.flags & dsp::frame_flag::cmd_missing, 0u);
}

TEST(ProgramSetPoint, AnotherProgramIsFlaggedByItsResidual) {
  Pair p = circle_without_setpoint();
  dsp::Program other = p.truth.meta.program;
  const auto pos = other.gcode.find("F2500");
  ASSERT_NE(pos, std::string::npos);
  other.gcode.replace(pos, 5, "F1500");  // the NC ran it at a 60 % feed override
  const auto a = apply_program_setpoint(p.daq, other, ProgramSetPointOptions{});
  EXPECT_GT(a.residual_ratio, 0.5);
  ASSERT_FALSE(a.flags.empty());
  EXPECT_EQ(a.flags.back().code, dsp::FlagCode::setpoint);
  EXPECT_NE(a.flags.back().detail.find("does not match the measured motion"), std::string::npos)
      << a.flags.back().detail;
}

TEST(ProgramSetPoint, McodeStopsAddAZeroDwellAfterTheTriggersOnly) {
  const std::string g = "G0 X1\nM101 (start)\nG1 X2 F100 (M102 in a comment)\nm102\nM5\nM103 ; end\n";
  EXPECT_EQ(with_mcode_stops(g),
            "G0 X1\nM101 (start)\nG4 P0\nG1 X2 F100 (M102 in a comment)\nm102\nG4 P0\nM5\nM103 ; end\nG4 P0\n");
}

TEST(ProgramCatalog, NamesTheMissingProgramFile) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("eical-programs-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "7.toml")
      << "[program]\nkind = \"circle\"\nradius_mm = 10.0\ngcode = \"\"\"\nG0 X10\nM101\nG1 X0 F100\nM103\n\"\"\"\n";
  const ProgramCatalog catalog(dir);
  EXPECT_EQ(catalog.program(7).kind, eical::dsp::ProgramKind::circle);
  try {
    (void)catalog.program(8);
    FAIL() << "program 8 does not exist";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "8.toml").string()), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace eical::drivers
