// The uncertainty's draws on several threads (drivers::thread_for) give exactly the U the
// same draws give one after another: each draw is seeded by its number and the sums are
// taken in draw order, so no figure depends on the executor or the number of cores.
#include "drivers/exec/thread_for.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"
#include "tests/support/same_uncertainty.hpp"
#include "tools/plan/test_plan.hpp"

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
  o.uncertainty.parallel = drivers::thread_for(3);
  const dsp::Analysis threads = dsp::analyze_run(run, o);
  eical::testing::expect_same_uncertainty(one, threads);
}

}  // namespace
}  // namespace eical::tools::plan
