#include "dsp/core/float_limits.hpp"
#include "dsp/core/frame.hpp"
#include "dsp/core/interpolate.hpp"
#include "dsp/core/units.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace eical::dsp {

TEST(Frame, DefaultHasNoReferenceAndNoFlags) {
  Frame f;
  EXPECT_TRUE(std::isnan(f.ref_mm[0]));
  EXPECT_EQ(f.flags, 0u);
  EXPECT_EQ(f.trigger, 0);
}

TEST(Units, FeedConversion) { EXPECT_NEAR(units::mm_per_min_to_mps(2500.0), 0.041666667, 1e-9); }

TEST(Interpolate, BetweenSamplesClampedAtTheEndsAndNaNWhenEmpty) {
  const std::vector<Eigen::Vector3d> x = {{0.0, 10.0, 0.0}, {1.0, 20.0, 0.0}, {3.0, 40.0, 0.0}};
  // Positions read at run time: folded as constants, GCC 12 warns of the branches the clamps
  // never take (-Warray-bounds).
  const std::vector<double> pos = {0.5, 1.25, -3.0, 7.0, 1e300, kNaN};
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[0], 0), 0.5);
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[1], 1), 25.0);
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[2], 1), 10.0);    // before the first sample: the first
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[3], 0), 3.0);     // past the last: the last
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[4], 0), 3.0);     // far past it: no cast to an index
  EXPECT_DOUBLE_EQ(interpolate_at(x, pos[5], 0), 0.0);     // no position: the first, never a wild index
  EXPECT_TRUE(std::isnan(interpolate_at({}, pos[0], 0)));  // nothing to interpolate
}

}  // namespace eical::dsp
