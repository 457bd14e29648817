// eical plan against simulation: for four programs the U predicted before the test lies
// within 30 % of what 20 simulated repeats on machines within the data sheet's tolerances
// show against the truth (tools/plan/plan_check.hpp; bench_plan prints the same table).
#include "tools/plan/plan_check.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::tools::plan {
namespace {

TEST(PlanCheck, PredictedUncertaintyWithinThirtyPercentOfTwentyRepeats) {
  const auto programs = check_programs();
  ASSERT_GE(programs.size(), 4u);
  std::vector<CheckRow> all;
  for (const auto& p : programs) {
    const auto rows = check_plan(p, 20, 60);
    all.insert(all.end(), rows.begin(), rows.end());
  }
  std::fputs(check_table(all).c_str(), stdout);
  for (const auto& r : all) {
    EXPECT_GE(r.repeats, 15) << r.program << ": too many repeats degraded";
    EXPECT_NEAR(r.ratio(), 1.0, 0.3) << r.program << " " << r.key;
  }
}

}  // namespace
}  // namespace eical::tools::plan
