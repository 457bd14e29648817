// Static compensation (ch. 6.3, Bild 6-19) against the simulator with each effect on:
// temperature (6-16), nonlinearity (6-17), cross-axis terms and mounting misalignment (6-18).
#include "pipeline_test_util.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cstdio>

namespace eical {
namespace {

using testutil::config_for;
using testutil::ideal_adc;
using testutil::run_pipeline;

// What an effect leaves in the position: the same program simulated with and without it,
// both through the same pipeline (noiseless, near-ideal ADC, no ZUPT), max |difference| in
// µm. The pipeline's common residual (the d³/6 jerk term of 6-38) cancels in the difference.
// The reference run is processed with its own data sheet and the same options.
double effect_um(const dsp::Run& with_effect, const dsp::Run& reference, const dsp::PipelineConfig& cfg) {
  dsp::PipelineConfig cfg_ref = cfg;
  for (int s = 0; s < 2; ++s) cfg_ref.sensors[s] = reference.meta.sensors[s];
  return testutil::max_difference_um(run_pipeline(with_effect, cfg), run_pipeline(reference, cfg_ref));
}

TEST(StaticCompEffects, TemperatureCompensationRemovesTheWarmingBiasDrift) {
  // The table sensor warms by up to 10 °C with a 20 s time constant (0.5 °C/s at the
  // start): with α_b = 100 µg/°C its bias drifts 50 µg/s, with α_k = 70 ppm/°C the 1 g on
  // z changes too. (Both sensors warming alike would cancel in head − table.)
  const sim::Scenario ref = ideal_adc(sim::step_scenario(0.0, 50.0, 3250.0, 1));
  sim::Scenario sc = ref;
  sc.truth[0].temperature = {20.0, 10.0, 20.0};
  const dsp::Run run = sim::simulate(sc), run_ref = sim::simulate(ref);
  auto cfg = config_for(run);
  cfg.zupt = false;  // the drift itself, not what ZUPT leaves of it
  const double e_with = effect_um(run, run_ref, cfg);
  // ZUPT's view: the velocity left at the final rest is the integrated drift.
  auto cfg_zupt = config_for(run);
  const auto with_zupt = run_pipeline(run, cfg_zupt);
  cfg.static_comp.temperature = cfg_zupt.static_comp.temperature = false;
  const double e_without = effect_um(run, run_ref, cfg);
  const auto without_zupt = run_pipeline(run, cfg_zupt);
  std::printf(
      "table warming 0.5 C/s: position error from it (no ZUPT): (6-16) off %.2f um, on %.4f um; velocity at the "
      "final rest off %.3f um/s, on %.5f um/s\n",
      e_without, e_with, without_zupt.zupt_velocity_error_mm_s.norm() * 1e3,
      with_zupt.zupt_velocity_error_mm_s.norm() * 1e3);
  EXPECT_GT(e_without, 10.0);  // 50 µg/s over seconds: ½·ḃ·t³/3 is tens of µm and more
  EXPECT_LT(e_with, 0.02 * e_without);
  EXPECT_LT(with_zupt.zupt_velocity_error_mm_s.norm(), 0.02 * without_zupt.zupt_velocity_error_mm_s.norm());
}

TEST(StaticCompEffects, NonlinearityCompensationRemovesTheSquareTerm) {
  // A strongly nonlinear sensor (k2 = 5e-3 1/g on every axis, data sheet = truth) on a
  // fast step: 2 m/s² gives k2 a² = 20 µg in every acceleration phase, all of one sign.
  sim::Scenario ref = ideal_adc(sim::step_scenario(0.0, 100.0, 6500.0, 1));
  for (int s = 0; s < 2; ++s) {
    ref.meta.sensors[s].k2_g_per_g2.setZero(), ref.meta.sensors[s].k3_g_per_g3.setZero();
    ref.truth[s].spec = ref.meta.sensors[s];
  }
  sim::Scenario sc = ref;
  for (int s = 0; s < 2; ++s) {
    sc.meta.sensors[s].k2_g_per_g2 = Eigen::Vector3d::Constant(5e-3);
    sc.truth[s].spec.k2_g_per_g2 = sc.meta.sensors[s].k2_g_per_g2;
  }
  const dsp::Run run = sim::simulate(sc), run_ref = sim::simulate(ref);
  auto cfg = config_for(run);
  cfg.zupt = false;
  const double e_with = effect_um(run, run_ref, cfg);
  cfg.static_comp.nonlinearity = false;
  const double e_without = effect_um(run, run_ref, cfg);
  std::printf("k2 = 5e-3/g, 100 mm at 6.5 m/min: position error from it (no ZUPT): (6-17) off %.3f um, on %.5f um\n",
              e_without, e_with);
  EXPECT_GT(e_without, 1.0);
  EXPECT_LT(e_with, 0.001 * e_without);
}

TEST(StaticCompEffects, CorrectionMatrixRemovesCrossAxisAndMisalignment) {
  // Table sensor turned 5 mrad about z against the data sheet, with 2e-3 / −1.5e-3 g/g
  // cross-axis sensitivity between x and y: on an R10 circle each couples one axis'
  // acceleration into the other. A calibration that knows them sets (6-18).
  const sim::Scenario ref = ideal_adc(sim::circle_scenario(10.0, 2500.0, 1));
  sim::Scenario sc = ref;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(5e-3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  sc.truth[0].spec.to_machine = sc.meta.sensors[0].to_machine * turn;
  sc.truth[0].k_cross_g_per_g(0, 1) = 2e-3;
  sc.truth[0].k_cross_g_per_g(1, 0) = -1.5e-3;
  const dsp::Run run = sim::simulate(sc), run_ref = sim::simulate(ref);
  auto cfg = config_for(run);
  cfg.zupt = false;
  const auto reference = run_pipeline(run_ref, cfg);
  const double e_data_sheet = testutil::max_difference_um(run_pipeline(run, cfg), reference);
  cfg.calibration[0].mounting = turn;
  const double e_mounting = testutil::max_difference_um(run_pipeline(run, cfg), reference);
  cfg.calibration[0].cross_g_per_g = sc.truth[0].k_cross_g_per_g;
  const double e_full = testutil::max_difference_um(run_pipeline(run, cfg), reference);
  std::printf(
      "R10 circle, 5 mrad + cross-axis: position error from them: data sheet %.3f um, mounting corrected %.3f um, "
      "mounting and cross-axis %.5f um\n",
      e_data_sheet, e_mounting, e_full);
  EXPECT_GT(e_data_sheet, 10.0);  // 5 mrad of a 10 mm radius is 50 µm of rotation
  EXPECT_LT(e_mounting, e_data_sheet);
  EXPECT_LT(e_full, 0.001 * e_data_sheet);
}

}  // namespace
}  // namespace eical
