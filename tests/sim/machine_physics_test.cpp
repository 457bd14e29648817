// The machine model: each error shows up in the true relative position (what the
// reference reads) the way it is defined, and the sensors see exactly that motion.
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::sim {
namespace {

Scenario quiet(Scenario sc) {
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;
  return sc;
}

// Relative-position deviation from the set-point on axis `a` (µm), every frame.
std::vector<double> deviation_um(const dsp::Run& run, const std::vector<Eigen::Vector3d>& truth, int a) {
  std::vector<double> d(truth.size());
  for (std::size_t n = 0; n < truth.size(); ++n) d[n] = (truth[n][a] - run.frames[n].cmd_mm[a]) * 1e3;
  return d;
}

TEST(MachinePhysics, ServoLagIsFeedforwardShortfallOverKv) {
  Scenario sc = quiet(step_scenario(0.0, 50.0, 3000.0, 1));
  sc.machine.servo[0] = {30.0, 0.9, 0.0};
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  // Mid-move at constant feed: lag = (1 − ff) v / Kv = 0.1 · 50 mm/s / 30 /s = 166.7 µm.
  std::size_t mid = 0;
  for (std::size_t n = 0; n < run.frames.size(); ++n)
    if (run.frames[n].cmd_mm[0] > 25.0) {
      mid = n;
      break;
    }
  EXPECT_NEAR(-deviation_um(run, truth, 0)[mid], 0.1 * 50.0 / 30.0 * 1e3, 0.5);
  // There and back: it settles at the start position again.
  EXPECT_NEAR(truth.back().x(), 0.0, 1e-6);
}

TEST(MachinePhysics, BacklashIsLostMotionAtReversal) {
  Scenario sc = quiet(circle_scenario(10.0, 2500.0, 1));
  sc.machine.backlash_um[0] = 5.0;
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dx = deviation_um(run, truth, 0), dy = deviation_um(run, truth, 1);
  const auto [lo, hi] = std::minmax_element(dx.begin(), dx.end());
  EXPECT_NEAR(*hi - *lo, 5.0, 1e-6);
  EXPECT_NEAR(*std::max_element(dy.begin(), dy.end(), [](double a, double b) { return std::abs(a) < std::abs(b); }),
              0.0, 1e-9);
}

TEST(MachinePhysics, SquarenessTiltsYIntoMinusX) {
  Scenario sc = quiet(circle_scenario(10.0, 2500.0, 1));
  sc.machine.squareness_urad[0] = 50.0;
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dx = deviation_um(run, truth, 0);
  for (std::size_t n = 0; n < truth.size(); n += 997) EXPECT_NEAR(dx[n], -50e-6 * run.frames[n].cmd_mm[1] * 1e3, 1e-9);
}

TEST(MachinePhysics, CyclicAndScaleErrorsFollowThePosition) {
  Scenario sc = quiet(step_scenario(0.0, 50.0, 3000.0, 1));
  sc.machine.scale_ppm[0] = 40.0;
  sc.machine.cyclic[0] = {1.5, 10.0, 30.0};
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dx = deviation_um(run, truth, 0);
  for (std::size_t n = 0; n < truth.size(); n += 733) {
    const double x = run.frames[n].cmd_mm[0];
    const double expect =
        40e-6 * x * 1e3 + 1.5 * std::sin(2 * std::numbers::pi * x / 10.0 + 30.0 * std::numbers::pi / 180.0);
    EXPECT_NEAR(dx[n], expect, 1e-9);
  }
}

TEST(MachinePhysics, StraightnessBowsTheOtherAxis) {
  Scenario sc = quiet(step_scenario(0.0, 50.0, 3000.0, 1));
  sc.machine.straightness[0] = {1, 3.0, {0.0, 50.0}};
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dy = deviation_um(run, truth, 1);
  double peak = 0.0;
  for (double v : dy) peak = std::max(peak, v);
  EXPECT_NEAR(peak, 3.0, 1e-3);        // at mid-span
  EXPECT_NEAR(dy.front(), 0.0, 1e-9);  // at the span's ends
  EXPECT_NEAR(dy.back(), 0.0, 1e-9);
}

TEST(MachinePhysics, ReversalSpikePeaksAtItsAmplitudeAfterEachReversal) {
  Scenario sc = quiet(circle_scenario(10.0, 2500.0, 1));
  sc.machine.spike[1] = {2.0, 15.0};
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dy = deviation_um(run, truth, 1);
  double peak = 0.0;
  for (double v : dy) peak = std::max(peak, std::abs(v));
  EXPECT_NEAR(peak, 2.0, 0.05);  // overlapping tails of neighbouring reversals are < 1e-3 here
}

TEST(MachinePhysics, StickSlipIsASawtoothBelowTheCreepFeed) {
  Scenario sc = quiet(gcode_scenario("G90 G21 G17 G61\nG0 X0\nG4 P0.3\nG1 X0.5 F60\nG4 P0.3\n"));
  sc.machine.stick_slip[0] = {1.0, 100.0, 2.0};
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dx = deviation_um(run, truth, 0);
  // At 1 mm/s the slide sticks 1 ms until it lags 1 µm, then slips forward in 2 ms (the lag
  // still grows while it gathers speed, to ≈ 1.25 µm): about 160 cycles over the 0.5 s of creep.
  int slips = 0;
  double worst = 0.0;
  for (std::size_t n = 1; n < dx.size(); ++n) {
    worst = std::min(worst, dx[n]);
    if (dx[n - 1] < -0.5 && dx[n] >= -0.5) ++slips;
  }
  EXPECT_LT(worst, -1.0);
  EXPECT_GT(worst, -1.0 - 1.0 * 2e-3 * 0.25 * 1e3);  // at most a quarter slip of set-point progress more
  EXPECT_GT(slips, 130);
  EXPECT_LT(slips, 190);
}

TEST(MachinePhysics, DifferentialModeIsRealRelativeMotionCommonModeIsNot) {
  Scenario base = quiet(step_scenario(0.0, 50.0, 3250.0, 1));
  for (auto& t : base.truth)
    t.spec.k2_g_per_g2.setZero(), t.spec.k3_g_per_g3.setZero();  // no mixing of motion and vibration
  Scenario diff = base, common = base;
  diff.differential_vibration = DriveMode{9.0, 0.03, Eigen::Vector3d(0.01, 0.0, 0.0)};
  common.common_vibration.mode = DriveMode{9.0, 0.03, Eigen::Vector3d(0.01, 0.0, 0.0)};
  common.common_vibration.tones.push_back({100.0, Eigen::Vector3d(3.0, 0.0, 0.0), 0.0});
  std::vector<Eigen::Vector3d> t_base, t_diff, t_common;
  const dsp::Run r_base = simulate(base, &t_base), r_diff = simulate(diff, &t_diff),
                 r_common = simulate(common, &t_common);
  double diff_peak = 0.0, common_peak = 0.0, table_change = 0.0, rel_change = 0.0;
  for (std::size_t n = 0; n < t_base.size(); ++n) {
    diff_peak = std::max(diff_peak, std::abs(t_diff[n].x() - t_base[n].x()) * 1e3);
    common_peak = std::max(common_peak, std::abs(t_common[n].x() - t_base[n].x()) * 1e3);
    // Common vibration moves both sensors alike: each sees it, their difference does not.
    const double dt = r_common.frames[n].accel_counts[0] - r_base.frames[n].accel_counts[0];
    const double dh = r_common.frames[n].accel_counts[3] - r_base.frames[n].accel_counts[3];
    table_change = std::max(table_change, std::abs(dt));
    rel_change = std::max(rel_change, std::abs(dh - dt));
  }
  // 9 Hz mode: static deflection gain·a/ω² = 0.01·2000/(2π·9)² = 6.3 µm, rings up on the ramps.
  EXPECT_GT(diff_peak, 3.0);
  EXPECT_EQ(common_peak, 0.0);
  EXPECT_GT(table_change, 1e6);                // 1 nV counts: ≥ 1 mV ≈ 0.8 mg of vibration
  EXPECT_LT(rel_change, 1e-6 * table_change);  // identical sensors: the same counts
}

TEST(MachinePhysics, DifferentialToneMovesTheHeadAgainstTheTable) {
  Scenario sc = quiet(circle_scenario(10.0, 2500.0, 1));
  sc.differential_tones.push_back({45.0, Eigen::Vector3d(10.0, 0.0, 0.0), 0.0});
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = simulate(sc, &truth);
  const auto dx = deviation_um(run, truth, 0);
  const auto [lo, hi] = std::minmax_element(dx.begin(), dx.end());
  const double w = 2 * std::numbers::pi * 45.0;
  EXPECT_NEAR((*hi - *lo) / 2.0, 10e-3 * sc.meta.site.g_mps2 / (w * w) * 1e6, 0.01);  // 1.23 µm
}

TEST(MachinePhysics, SensorsSeeExactlyTheMachinesMotion) {
  // All machine errors at once; the pipeline's integrated relative acceleration must equal
  // what the reference reads (noise-free): the second differences the sensors get are
  // those of the true positions.
  Scenario sc = quiet(circle_scenario(10.0, 2500.0, 2));
  for (auto& s : sc.machine.servo) s = {31.4, 0.99, 0.0};
  sc.machine.servo[1].kv_per_s = 25.0;
  sc.machine.squareness_urad[0] = 40.0;
  sc.machine.scale_ppm[0] = 60.0;
  sc.machine.cyclic[1] = {1.0, 5.0, 0.0};
  sc.machine.straightness[0] = {1, 2.0, {-10.0, 10.0}};
  sc.machine.spike[1] = {2.0, 15.0};
  sc.differential_vibration = DriveMode{9.0, 0.03, Eigen::Vector3d(0.005, 0.005, 0.0)};
  const dsp::Run run = simulate(sc);
  // Without ZUPT: the machine still settles (servo lag, the head's 9 Hz mode) when the
  // set-point stops, which a ZUPT would wrongly call rest.
  dsp::AnalysisOptions no_zupt;
  no_zupt.zupt = false;
  const dsp::Measurement m = dsp::analyze_run(run, no_zupt).measurement;
  double ss = 0.0, moved = 0.0;
  // The pipeline starts at the set-point; the reference reads the machine's deviation
  // there too: compare from the same start.
  const Eigen::Vector3d offset = m.pos_mm[0] - m.ref_mm[0];
  for (std::size_t i = 0; i < m.pos_mm.size(); ++i) {
    ss += (m.pos_mm[i] - m.ref_mm[i] - offset).head<2>().squaredNorm();
    moved = std::max(moved, (m.ref_mm[i] - m.cmd_mm[i]).head<2>().norm());
  }
  const double rms_um = std::sqrt(ss / static_cast<double>(m.pos_mm.size())) * 1e3;
  std::printf("machine errors up to %.1f um; pipeline vs reference %.4f um RMS\n", moved * 1e3, rms_um);
  EXPECT_GT(moved * 1e3, 5.0);
  EXPECT_LT(rms_um, 0.15);  // the ideal machine gives 0.093 µm here (ramp jerk steps, no ZUPT)
}

}  // namespace
}  // namespace eical::sim
