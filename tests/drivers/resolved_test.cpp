// Reading a figure and its uncertainty from an eical-result/1 document by result key, and
// the rule `eical comp` and the reports share: resolved ⇔ |value| > U.
#include "drivers/results/resolved.hpp"

#include <gtest/gtest.h>

namespace eical::drivers {
namespace {

const nlohmann::json kDoc = nlohmann::json::parse(R"({
  "circle": {"circular_deviation_G_um": 6.3, "radius_mean_deviation_um": -0.4},
  "diagnostics": {"backlash_x_um": 0.3, "servo_mismatch_ms": null},
  "positioning": {"vdi3441": {"P_um": 4.0}, "per_target": [{"mean_um": 1.5}, {"mean_um": -0.2}, {"mean_um": 3.0}]},
  "rectangle": {"corner_errors_um": [[1.0, -4.0], [0.1, 0.2]]},
  "uncertainty_k2": {"circle.circular_deviation_G_um": 1.1, "circle.radius_mean_deviation_um": 0.8,
                     "diagnostics.backlash_x_um": 0.4, "positioning.vdi3441.P_um": 1.0,
                     "positioning.per_target.mean_um": [0.5, 0.5, null],
                     "rectangle.corner_errors_um": [[0.5, 0.5], [0.5, 0.5]]}
})");

TEST(ResolvedFigures, ScalarsNestedArraysAndPairs) {
  EXPECT_TRUE(figure_resolved(kDoc, "circle.circular_deviation_G_um"));
  EXPECT_FALSE(figure_resolved(kDoc, "circle.radius_mean_deviation_um"));  // 0.4 ≤ 0.8
  EXPECT_FALSE(figure_resolved(kDoc, "diagnostics.backlash_x_um"));        // 0.3 ≤ 0.4
  EXPECT_FALSE(figure_resolved(kDoc, "diagnostics.servo_mismatch_ms"));    // null: never resolved
  EXPECT_TRUE(figure_resolved(kDoc, "positioning.vdi3441.P_um"));
  EXPECT_EQ(figure_values(kDoc, "positioning.per_target.mean_um").size(), 3u);
  EXPECT_TRUE(figure_resolved(kDoc, "positioning.per_target.mean_um", 0));
  EXPECT_FALSE(figure_resolved(kDoc, "positioning.per_target.mean_um", 1));
  EXPECT_FALSE(figure_resolved(kDoc, "positioning.per_target.mean_um", 2));  // no U: not resolved
  EXPECT_TRUE(figure_resolved(kDoc, "rectangle.corner_errors_um", 0));       // corner 1, x
  EXPECT_TRUE(figure_resolved(kDoc, "rectangle.corner_errors_um", 1));       // corner 1, y
  EXPECT_FALSE(figure_resolved(kDoc, "rectangle.corner_errors_um", 2));
  EXPECT_FALSE(figure_resolved(kDoc, "circle.no_such_figure_um"));
  ASSERT_TRUE(uncertainty_k2(kDoc, "circle.circular_deviation_G_um"));
  EXPECT_DOUBLE_EQ(*uncertainty_k2(kDoc, "circle.circular_deviation_G_um"), 1.1);
  EXPECT_FALSE(figure_value(kDoc, "diagnostics.servo_mismatch_ms"));
}

}  // namespace
}  // namespace eical::drivers
