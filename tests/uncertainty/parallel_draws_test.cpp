// The analysis on several threads (drivers::thread_for: the smoother's axes, the
// uncertainty's draws) gives exactly the path and the U it gives one task after another:
// the axes are independent, each draw is seeded by its number and the sums are taken in
// draw order, so no figure depends on the executor or the number of cores.
#include "drivers/exec/thread_for.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"
#include "tests/support/same_uncertainty.hpp"
#include "tools/plan/predicted_uncertainty.hpp"

#include <gtest/gtest.h>

namespace eical::tools::plan {
namespace {

TEST(ParallelDraws, ThreadsGiveTheSameUncertaintyAsOneAfterAnother) {
  TestProgram p;  // circle R10 F2500, two PSD strips: every diagnostic and circle figure
  p.repeats = 2;
  p.psd = strips_for(p);
  const dsp::Run run = sim::simulate(scenario_of(p, 3));
  dsp::AnalysisOptions o;
  o.uncertainty.draws = 24;
  const dsp::Analysis one = dsp::analyze_run(run, o);
  o.parallel = drivers::thread_for(3);
  const dsp::Analysis threads = dsp::analyze_run(run, o);
  eical::testing::expect_same_uncertainty(one, threads);
  // The smoother's axes ran side by side too: the corrected path is the same, bit for bit.
  ASSERT_EQ(one.measurement.pos_mm.size(), threads.measurement.pos_mm.size());
  for (std::size_t i = 0; i < one.measurement.pos_mm.size(); ++i)
    ASSERT_EQ(one.measurement.pos_mm[i], threads.measurement.pos_mm[i]) << "sample " << i;
}

}  // namespace
}  // namespace eical::tools::plan
