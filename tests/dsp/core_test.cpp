#include "dsp/core/frame.hpp"
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

}  // namespace eical::dsp
