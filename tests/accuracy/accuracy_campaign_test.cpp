// The accuracy campaign on one drawn machine: identified on site, every figure within
// twice the target (the benchmark prints the figures themselves), and the data
// sheet far worse (what the identification buys).
#include "tests/support/accuracy_campaign.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::tools::accuracy {
namespace {

TEST(AccuracyCampaign, IdentifiedSensorsMeetTwiceTheTargetsAndTheBoundsAreHonest) {
  Options o;
  o.seed = 7;
  const Report r = run(o);
  std::fputs(table(r).c_str(), stdout);
  ASSERT_TRUE(r.calibrated);
  ASSERT_GE(r.figures.size(), 9u);
  for (const auto& f : r.figures) {
    EXPECT_LE(f.measured, 2.0 * f.target) << f.name;
    EXPECT_GT(f.bound, 0.0) << f.name;
    EXPECT_LT(f.ratio(), 6.0) << f.name << ": far from the noise limit";
  }
  o.calibrate = false;
  const Report sheet = run(o);
  EXPECT_GT(sheet.figures.front().measured, 5.0 * r.figures.front().measured);  // circle RMS
}

}  // namespace
}  // namespace eical::tools::accuracy
