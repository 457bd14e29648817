// Coriolis correction (3-6) with the velocity fed back, on a long fast move with the
// simulator's Earth rate on.
#include "pipeline_test_util.hpp"

#include "dsp/core/units.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace eical {
namespace {

namespace units = dsp::units;

using testutil::config_for;
using testutil::ideal_adc;
using testutil::max_error_um;
using testutil::run_pipeline;
using testutil::simulate_with_truth;

TEST(Coriolis, FedBackVelocityRemovesTheEarthRateError) {
  // x (table, heading 0: north) 200 mm at 10 m/min and back: (3-5) gives
  // 2 Ω v sin φ ≈ 2e-6 g across the motion, in y.
  sim::Scenario sc = ideal_adc(sim::step_scenario(0.0, 200.0, 10000.0, 1));
  sc.coriolis = true;
  const auto sr = simulate_with_truth(sc);
  auto cfg = config_for(sr.run);
  cfg.zupt = false;
  const auto without = run_pipeline(sr.run, cfg);
  cfg.coriolis = true;
  const auto with = run_pipeline(sr.run, cfg);
  const double e_without = max_error_um(without, sr.true_mm, 1), e_with = max_error_um(with, sr.true_mm, 1);
  // (3-5) and (4-3) for the thesis' example (10 m/min at 50°, 1 s) and for this site.
  const double v_mps = units::mm_per_min_to_mps(10000.0);
  const double thesis_um = 0.5 * 2.0 * units::kEarthRateRadps * v_mps * std::sin(units::deg_to_rad(50.0)) * 1e6;
  std::printf(
      "Coriolis, 200 mm at 10 m/min (latitude %.1f): max y error without correction %.2f um, with %.4f um "
      "(thesis example, 1 s at 10 m/min, 50 deg: %.2f um by (3-5))\n",
      sc.meta.site.latitude_deg, e_without, e_with, thesis_um);
  EXPECT_GT(e_without, thesis_um);  // 1.2 s at 51.3° is longer and further north
  EXPECT_LT(e_with, 0.01 * e_without);
  // With ZUPT the velocity left at the end is removed, not the error inside the move.
  auto cfg_zupt = config_for(sr.run);
  const double z_without = max_error_um(run_pipeline(sr.run, cfg_zupt), sr.true_mm, 1);
  cfg_zupt.coriolis = true;
  const double z_with = max_error_um(run_pipeline(sr.run, cfg_zupt), sr.true_mm, 1);
  std::printf("with ZUPT: max y error without correction %.2f um, with %.4f um\n", z_without, z_with);
  EXPECT_LT(z_with, 0.05 * z_without);
}

TEST(Coriolis, EarthRateInMachineAxesFollowsTheSite) {
  dsp::Site site;
  site.latitude_deg = 50.0, site.heading_deg = 90.0;  // +X east
  const Eigen::Vector3d w = dsp::earth_rate_machine_radps(site);
  EXPECT_NEAR(w.norm(), units::kEarthRateRadps, 1e-12);
  EXPECT_NEAR(w[0], 0.0, 1e-12);  // no north component along east
  EXPECT_NEAR(w[2], units::kEarthRateRadps * std::sin(units::deg_to_rad(50.0)), 1e-12);
  // (3-6) removes exactly 2 ω × v for the velocity fed back.
  const dsp::CoriolisComp c(site);
  const Eigen::Vector3d sensed = c.two_omega_radps.cross(Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_EQ(c.apply(sensed, Eigen::Vector3d(0.0, 1.0, 0.0)), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace eical
