// The compensation table's one sign convention, the lost motion folded into it, and the
// checks that keep a table from being used where nothing was measured.
#include "dsp/comp/axis_table.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

namespace eical::dsp::comp {
namespace {

TEST(AxisTable, CorrectionIsMinusTheDeviationAndTheFoldedPlayGivesISO230_2sB) {
  const AxisTable t = fold_lost_motion(0, {0.0, 10.0, 20.0}, {0.0, 1.0, 2.0}, 4.0);
  // A play b: approached in + the slide stops b/2 short (forward − reverse = B = −b).
  EXPECT_DOUBLE_EQ(t.forward_um[1], -1.0);
  EXPECT_DOUBLE_EQ(t.reverse_um[1], 3.0);
  EXPECT_DOUBLE_EQ(t.mean_lost_motion_um(), 4.0);
  EXPECT_DOUBLE_EQ(t.correction_um(5.0, Approach::forward), 1.5);    // −(0.5 − 2)
  EXPECT_DOUBLE_EQ(t.correction_um(-5.0, Approach::reverse), -2.0);  // held beyond the end
  EXPECT_DOUBLE_EQ(residual_after_um(t, t), 0.0);
  EXPECT_DOUBLE_EQ(residual_after_um(t, without_reversal(t)), 2.0);  // the play left: ±b/2
}

TEST(AxisTable, ResampleNeverExtrapolatesAndCoverageNamesTheGap) {
  const AxisTable t = fold_lost_motion(1, {0.0, 10.0, 40.0}, {0.0, 2.0, 8.0}, 0.0);
  const AxisTable g = resample(t, 0.0, 10.0, 5);
  EXPECT_DOUBLE_EQ(g.forward_um[2], 4.0);  // 20 mm, between the points 10 and 40
  EXPECT_THROW((void)resample(t, 0.0, 10.0, 6), InputError);
  try {
    require_coverage(t, -10.0, 10.0, "circle run c1 measured");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "comp: the y table covers 0 .. 40 mm, but circle run c1 measured y from -10 to 10 mm: measure "
              "positioning over that range (beyond "
              "its ends a control holds the end value)");
  }
  EXPECT_NO_THROW(require_coverage(t, 0.0, 40.0, "x"));
}

TEST(AxisTable, ValidateNamesThePoint) {
  AxisTable t = fold_lost_motion(2, {0.0, 5.0, 5.0}, {0.0, 1.0, 2.0}, 0.0);
  try {
    validate(t);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("z table: positions must increase; point 3 (5 mm) follows 5 mm"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eical::dsp::comp
