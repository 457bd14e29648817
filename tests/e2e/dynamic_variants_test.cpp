// The dynamic compensation at the acceleration, velocity and position level (ch. 6.3.3,
// 6-33 … 6-35) and the two-stage form (6-38), each with the DAQ delay, on a noiseless PT2
// with a near-ideal ADC: they must reach the same result.
#include "pipeline_test_util.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical {
namespace {

using testutil::config_for;
using testutil::ideal_adc;
using testutil::max_difference_um;
using testutil::max_error_um;
using testutil::run_pipeline;
using testutil::simulate_with_truth;

void check_variants_agree(const sim::Scenario& sc, const char* what) {
  const auto sr = simulate_with_truth(ideal_adc(sc));
  auto cfg = config_for(sr.run);
  cfg.zupt = false;  // the compensation alone
  cfg.dynamic = dsp::DynamicComp::two_stage;
  const auto two_stage = run_pipeline(sr.run, cfg);
  cfg.dynamic = dsp::DynamicComp::none;
  const double e_none = max_error_um(run_pipeline(sr.run, cfg), sr.true_mm);
  const double e_two_stage = max_error_um(two_stage, sr.true_mm);
  std::printf("%s: max error vs truth: uncompensated %.1f um, two-stage (6-38) %.4f um\n", what, e_none, e_two_stage);
  EXPECT_LT(e_two_stage, 0.01 * e_none);
  for (auto mode :
       {dsp::DynamicComp::acceleration_level, dsp::DynamicComp::velocity_level, dsp::DynamicComp::position_level}) {
    cfg.dynamic = mode;
    const auto m = run_pipeline(sr.run, cfg);
    const double agree = max_difference_um(m, two_stage), err = max_error_um(m, sr.true_mm);
    std::printf("  %-34s max |x - x_two_stage| %.2e um, max error vs truth %.4f um\n", dsp::dynamic_comp_name(mode),
                agree, err);
    ASSERT_EQ(m.pos_mm.size(), two_stage.pos_mm.size());
    // Same result: the variants differ by their discrete derivatives only (transients at
    // the jerk steps), far below the common residual of the second-order inverse (d³/6·Δjerk).
    EXPECT_LT(agree, 0.05 * e_two_stage) << dsp::dynamic_comp_name(mode);
    EXPECT_LT(err, 0.01 * e_none) << dsp::dynamic_comp_name(mode);
  }
}

TEST(DynamicVariants, AllLevelsAgreeOnTheR10Circle) {
  check_variants_agree(sim::circle_scenario(10.0, 2500.0, 1), "R10 circle 2.5 m/min");
}

TEST(DynamicVariants, AllLevelsAgreeOnAFastStep) {
  check_variants_agree(sim::step_scenario(0.0, 50.0, 6500.0, 1), "50 mm step 6.5 m/min");
}

}  // namespace
}  // namespace eical
