// eical plan against simulation, the small version: for the circle of the check (sensors
// identified on site first; bench_plan runs all four programs) the U
// predicted before the test against what 10 simulated repeats on machines drawn within the
// data sheet's tolerances show against the truth (|mean error| + 2 sd). Ten repeats estimate
// that spread to about ±25 %, so the bound here is 40 %; bench_plan runs 20 repeats and
// prints the table the issue asks for (within 30 %). One test per program: each about a
// minute of simulation and identification.
#include "tools/plan/plan_check.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::tools::plan {
namespace {

constexpr int kRepeats = 10;
constexpr int kDraws = 100;  // as bench_plan and eical plan: U's estimate depends on the draws
constexpr double kBound = 0.4;

class PlanCheck : public ::testing::TestWithParam<std::string> {};

TEST_P(PlanCheck, PredictedUncertaintyMatchesTheSpreadOfSimulatedRepeats) {
  const auto programs = check_programs();
  ASSERT_GE(programs.size(), 4u);
  const TestProgram* p = nullptr;
  for (const auto& q : programs)
    if (dsp::program_kind_name(q.kind) == GetParam()) p = &q;
  ASSERT_NE(p, nullptr) << GetParam() << " is not among the check's programs";
  const auto rows = check_plan(*p, kRepeats, kDraws);
  std::fputs(check_table(rows).c_str(), stdout);
  ASSERT_FALSE(rows.empty());
  for (const auto& r : rows) {
    EXPECT_EQ(r.repeats, kRepeats) << r.program << ": repeats degraded or not evaluated";
    EXPECT_NEAR(r.ratio(), 1.0, kBound) << r.program << " " << r.key << ": U plan " << r.predicted_u << ", U sim "
                                        << r.empirical_u;
  }
}

// The circle, the test the plan is most asked about; the ISO 230-2 cycle, step and
// rectangle (each 1 to 1.5 min of CI's 45) are checked by bench_plan with its 20 repeats.
INSTANTIATE_TEST_SUITE_P(Programs, PlanCheck, ::testing::Values("circle"));

}  // namespace
}  // namespace eical::tools::plan
