// A simulated ISO 230-2 cycle through the pipeline: ZUPT at every target dwell keeps
// the inertial measurement within a few micrometres on an ideal machine.
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical {
namespace {

TEST(PositioningRun, SimulatedCycleEvaluatesAllRunsAndTargets) {
  const dsp::Run run = sim::simulate(sim::positioning_scenario({0.0, 10.0, 20.0, 30.0}, 3));
  const auto a = dsp::analyze_run(run);
  ASSERT_TRUE(a.positioning) << (a.flags.empty() ? "" : flag_text(a.flags.front()));
  EXPECT_EQ(a.positioning->runs, 3);
  EXPECT_EQ(a.positioning->targets.size(), 4u);
  std::printf("ideal machine, 0.4 ug/sqrt(Hz): A %.2f um, R %.2f um, B %.2f um\n", a.positioning->A_um,
              a.positioning->R_um, a.positioning->B_um);
  // The machine is ideal: what A shows is the measurement's own noise after the ZUPTs.
  EXPECT_LT(a.positioning->A_um, 25.0);
  EXPECT_GT(a.measurement.zupt_window_samples, 0u);
}

}  // namespace
}  // namespace eical
