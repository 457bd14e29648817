// The block-wise simulation of a servo-rate set-point against the batch simulation of
// the same set-point: what the windows change must stay far below the sensor noise.
#include "drivers/source/windowed_sim.hpp"
#include "drivers/source/source.hpp"
#include "sim/nc/sampled_set_point.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::drivers {
namespace {

// A LinuxCNC-like servo trajectory at 1 kHz: rest, x out and back (a reversal), a
// quarter circle, rest. Trapezoidal speed like LinuxCNC's planner.
// Distances along a path at 1 kHz with a trapezoidal speed profile (LinuxCNC's planner).
std::vector<double> trapezoid(double d_mm, double v_mm_s, double a_mm_s2) {
  std::vector<double> s;
  double x = 0, v = 0;
  while (x < d_mm) {
    const double brake = v * v / (2 * a_mm_s2);
    v = (d_mm - x <= brake) ? std::max(v - a_mm_s2 * 1e-3, 1e-3) : std::min(v + a_mm_s2 * 1e-3, v_mm_s);
    x = std::min(d_mm, x + v * 1e-3);
    s.push_back(x);
  }
  return s;
}

// A LinuxCNC-like servo trajectory at 1 kHz: rest, x out and back (a reversal), a
// quarter circle at F2500, rest.
std::vector<Eigen::Vector3d> servo_trajectory() {
  std::vector<Eigen::Vector3d> p(500, Eigen::Vector3d::Zero());
  auto rest = [&](int n) { p.insert(p.end(), static_cast<std::size_t>(n), p.back()); };
  auto move_x = [&](double dist_mm) {
    const Eigen::Vector3d p0 = p.back();
    for (double s : trapezoid(std::abs(dist_mm), 40, 1000))
      p.push_back(p0 + Eigen::Vector3d(dist_mm > 0 ? s : -s, 0, 0));
  };
  move_x(20);
  rest(300);
  move_x(-20);
  rest(200);
  const double r = 10;
  const Eigen::Vector3d c = p.back() - Eigen::Vector3d(r, 0, 0);
  for (double s : trapezoid(r * std::numbers::pi / 2, 41.667, 250))
    p.push_back(c + r * Eigen::Vector3d(std::cos(s / r), std::sin(s / r), 0));
  rest(500);
  return p;
}

sim::Scenario scenario() {
  sim::Scenario sc = sim::gcode_scenario("", eical::dsp::ProgramKind::freeform, 5);
  sc.noise = false;  // compare the deterministic signal; noise is drawn per window anyway
  sc.machine.backlash_um[0] = 4.0;
  sc.machine.scale_ppm[0] = 50.0;
  sc.machine.servo[0] = {33.3, 0.99, 0.0};
  sc.machine.servo[1] = {33.3, 0.99, 0.0};
  return sc;
}

TEST(WindowedSim, FramesMatchTheBatchSimulationWellBelowTheSensorNoise) {
  const auto traj = servo_trajectory();
  const sim::Scenario sc = scenario();
  const dsp::Run batch = sim::simulate(sc, sim::nc::SampledSetPoint(traj, 1000.0, {}));

  WindowedSim w(sc, {});
  std::vector<dsp::Frame> out;
  std::vector<dsp::Frame> block(w.frames_per_block() + 100);
  for (std::size_t k = 0; k < traj.size(); ++k) {
    w.push(traj[k]);
    if (w.block_ready())
      out.insert(out.end(), block.begin(), block.begin() + static_cast<std::ptrdiff_t>(w.simulate_block(block)));
  }
  out.insert(out.end(), block.begin(), block.begin() + static_cast<std::ptrdiff_t>(w.simulate_block(block, true)));
  ASSERT_EQ(out.size(), batch.frames.size()) << "one frame per DAQ sample of the trajectory, none twice";

  double worst_g = 0, worst_cmd_mm = 0;
  std::size_t worst_at = 0;
  const double k1 = sc.truth[0].spec.k1_v_per_g[0] / sc.meta.acquisition.adc_lsb_volt;  // counts per g
  for (std::size_t n = 0; n < out.size(); ++n) {
    ASSERT_EQ(out[n].sample_index, static_cast<std::int64_t>(n));
    for (int c = 0; c < 6; ++c) {
      const double d = std::abs(out[n].accel_counts[c] - batch.frames[n].accel_counts[c]) / k1;
      if (d > worst_g) worst_g = d, worst_at = n;
    }
    for (int a = 0; a < 3; ++a)
      worst_cmd_mm = std::max(worst_cmd_mm, std::abs(out[n].cmd_mm[a] - batch.frames[n].cmd_mm[a]));
  }
  // Sensor noise per sample at the data-sheet density and 10 kHz.
  const double noise_g = sc.truth[0].spec.noise_ug_per_rthz * 1e-6 * std::sqrt(sc.meta.acquisition.fs_hz);
  std::printf(
      "windowed vs batch: worst accel difference %.3g ug at frame %zu (noise per sample %.3g ug); set-point %.3g um\n",
      worst_g * 1e6, worst_at, noise_g * 1e6, worst_cmd_mm * 1e3);
  EXPECT_LT(worst_g, 0.1 * noise_g) << "block boundaries must not show in the accelerations";
  // Linear (frames) against cubic (batch) interpolation between servo samples: a·h²/8 for
  // the linear part, and the spline rounds the acceleration steps by as much again.
  EXPECT_LT(worst_cmd_mm, 2.0 * 1000.0 * 1e-6 / 8.0);
}

TEST(WindowedSim, RefusesEffectsItCannotContinueAcrossBlocks) {
  sim::Scenario sc = scenario();
  sc.truth[0].bias_rw_ug_per_rts = 1.0;
  sc.machine.stick_slip[1].amp_um = 1.0;
  try {
    WindowedSim w(sc, {});
    FAIL() << "accepted a bias random walk";
  } catch (const SourceError& e) {
    EXPECT_NE(std::string(e.what()).find("table bias random walk"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("stick-slip on y"), std::string::npos) << e.what();
  }
}

TEST(WindowedSim, RefusesAServoTooSlowForTheHistory) {
  sim::Scenario sc = scenario();
  sc.machine.servo[2] = {10.0, 0.0, 0.0};  // needs 0.8 s, history is 0.3 s
  EXPECT_THROW(WindowedSim(sc, {}), SourceError);
}

}  // namespace
}  // namespace eical::drivers
