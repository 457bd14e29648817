// Is U honest? A small seeded campaign (three machines drawn within the data sheet's
// tolerances, four programs each): the headline figures' errors against the simulator's
// truth must lie within U in at least 85 % of the cases (95 % expected; 30 cases) and U
// must not be inflated (median U at most 3× the RMS error). bench_uncertainty runs the
// full campaign and prints the table per figure.
#include "tools/uncertainty/coverage_campaign.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::tools::uncertainty {
namespace {

TEST(UncertaintyCoverage, HeadlineFiguresAreCoveredAndUIsNotInflated) {
  CampaignOptions o;
  o.seeds = {1, 2, 3};
  o.draws = 60;
  const CampaignResult r = run_campaign(o);
  std::fputs(coverage_table(r).c_str(), stdout);
  EXPECT_TRUE(r.failures.empty());
  EXPECT_EQ(r.runs, 12u);
  ASSERT_GE(r.headline.cases, 30u);
  EXPECT_GE(r.headline.coverage(), 0.85);
  EXPECT_LE(r.headline.median_u(), 3.0 * r.headline.rms_error());
  for (const char* key : {"circle.circular_deviation_G_um", "positioning.E_um", "step.end_position_error_um",
                          "rectangle.corner_error_max_um"})
    EXPECT_EQ(r.figures.count(key), 1u) << key << " was not evaluated";
}

}  // namespace
}  // namespace eical::tools::uncertainty
