// Is U honest? A small seeded campaign: the headline figures' errors against the
// simulator's truth must lie within U in at least 85 % of the cases (95 % expected) and U
// must not be inflated (median U at most 3× the RMS error). Circles (the background circle
// of each seed, data-sheet sensors) are cheap: twelve machines, as bench_uncertainty's
// default, so that two hard machines do not decide the test; positioning, step and
// rectangle on three. bench_uncertainty runs the full campaign and prints the table per
// figure.
#include "tests/support/coverage_campaign.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::coverage {
namespace {

CampaignResult campaign(std::vector<std::uint64_t> seeds, std::vector<std::string> programs) {
  CampaignOptions o;
  o.seeds = std::move(seeds);
  o.programs = std::move(programs);
  o.draws = 60;
  CampaignResult r = run_campaign(o);
  std::fputs(coverage_table(r).c_str(), stdout);
  EXPECT_TRUE(r.failures.empty());
  EXPECT_LE(r.headline.median_u(), 3.0 * r.headline.rms_error());
  return r;
}

TEST(UncertaintyCoverage, HeadlineFiguresAreCoveredAndUIsNotInflated) {
  const CampaignResult circles = campaign({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, {"circle"});
  const CampaignResult others = campaign({1, 2, 3}, {"step", "positioning", "rectangle"});
  EXPECT_EQ(circles.runs + others.runs, 21u);
  const std::size_t cases = circles.headline.cases + others.headline.cases;
  const std::size_t covered = circles.headline.covered + others.headline.covered;
  ASSERT_GE(cases, 60u);
  std::printf("headline figures, both campaigns pooled: %zu of %zu covered (%.1f %%)\n", covered, cases,
              100.0 * static_cast<double>(covered) / static_cast<double>(cases));
  EXPECT_GE(static_cast<double>(covered), 0.85 * static_cast<double>(cases));
  EXPECT_EQ(circles.figures.count("circle.circular_deviation_G_um"), 1u);
  for (const char* key : {"positioning.E_um", "step.end_position_error_um", "rectangle.corner_error_max_um"})
    EXPECT_EQ(others.figures.count(key), 1u) << key << " was not evaluated";
}

}  // namespace
}  // namespace eical::coverage
