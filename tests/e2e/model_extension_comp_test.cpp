// The model extensions eical explain can take over, compensated by the pipeline: damping
// that grows with the acceleration (ch. 8.3.1) and the DAQ skew of the head channels.
// Each on a noiseless simulation: told the true value, the pipeline's error from the
// effect falls to a part of what the nominal model leaves.
#include "pipeline_test_util.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical {
namespace {

using testutil::config_for;
using testutil::ideal_adc;
using testutil::max_error_um;
using testutil::run_pipeline;

TEST(ModelExtensionComp, AmplitudeDependentDampingIsCompensatedWhenTold) {
  // The table moves x at 6.5 m/min; its ζ grows by 1.2 per g of acceleration.
  sim::Scenario sc = ideal_adc(sim::step_scenario(0.0, 50.0, 6500.0, 1));
  sc.truth[0].zeta_per_g = 1.2;
  const testutil::SimRun r = testutil::simulate_with_truth(sc);
  auto cfg = config_for(r.run);
  cfg.zupt = false;  // the effect itself, not what the supports leave of it
  const double nominal = max_error_um(run_pipeline(r.run, cfg), r.true_mm, 0);
  cfg.sensors[0].zeta_per_g = 1.2;
  const double told = max_error_um(run_pipeline(r.run, cfg), r.true_mm, 0);
  // The same run without the effect: what the pipeline leaves anyway.
  sc.truth[0].zeta_per_g = 0.0;
  const testutil::SimRun r0 = testutil::simulate_with_truth(sc);
  auto cfg0 = config_for(r0.run);
  cfg0.zupt = false;
  const double floor = max_error_um(run_pipeline(r0.run, cfg0), r0.true_mm, 0);
  std::printf("zeta_per_g 1.2: x error nominal %.3f um, told %.3f um, without the effect %.3f um\n", nominal, told,
              floor);
  EXPECT_GT(nominal - floor, 0.5);  // the effect is there
  // The first-order term c·∫a|a|dt takes three quarters of it (measured: 2.83 → 0.64 µm);
  // what is left is beyond the first-order series (open, see the issue note).
  EXPECT_LT(std::abs(told - floor), 0.3 * (nominal - floor));
}

TEST(ModelExtensionComp, HeadChannelSkewIsCompensatedWhenTold) {
  // The head moves y (table x); its channels reach the DAQ 0.8 samples after the table's.
  sim::Scenario sc = ideal_adc(sim::circle_scenario(10.0, 2500.0, 1));
  sc.meta.machine.table_axes = {"x"}, sc.meta.machine.head_axes = {"y", "z"};
  sc.daq.skew_head_samples = 0.8;
  const testutil::SimRun r = testutil::simulate_with_truth(sc);
  auto cfg = config_for(r.run);
  cfg.zupt = false;
  const double nominal = max_error_um(run_pipeline(r.run, cfg), r.true_mm, 1);
  cfg.acquisition.daq_skew_head_samples = 0.8;
  const double told = max_error_um(run_pipeline(r.run, cfg), r.true_mm, 1);
  sc.daq.skew_head_samples = 0.0;
  const testutil::SimRun r0 = testutil::simulate_with_truth(sc);
  auto cfg0 = config_for(r0.run);
  cfg0.zupt = false;
  const double floor = max_error_um(run_pipeline(r0.run, cfg0), r0.true_mm, 1);
  std::printf("head skew 0.8 samples: y error nominal %.3f um, told %.3f um, without the skew %.3f um\n", nominal, told,
              floor);
  EXPECT_GT(nominal - floor, 1.0);
  EXPECT_LT(std::abs(told - floor), 0.1 * (nominal - floor));
}

}  // namespace
}  // namespace eical
