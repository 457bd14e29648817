// The SVG plots: scales that cover the data (and always terminate), escaped text.
#include "tools/report/svg.hpp"

#include <gtest/gtest.h>

#include <string>

namespace eical::tools::report {
namespace {

TEST(Svg, PolarScaleCoversTheLargestDeviationForAnyAmplitude) {
  // Amplitudes on both sides of the 1-2-5 steps (6.29 µm once looped forever).
  for (double amp : {0.03, 0.7, 2.0, 6.0, 6.29, 14.9, 55.0, 480.0}) {
    const std::string svg = polar_plot({{"a", kBlue, {0.0, 90.0, 180.0}, {amp, -amp, 0.5 * amp}}}, "t");
    const auto at = svg.find(" µm / division");
    ASSERT_NE(at, std::string::npos);
    const auto from = svg.rfind('>', at) + 1;
    const double scale = std::stod(svg.substr(from, at - from));
    EXPECT_GE(scale * 3, amp) << amp;  // three rings outside the reference circle
    EXPECT_LT(scale, amp) << amp;      // and not absurdly coarse
  }
}

TEST(Svg, LinePlotTicksOnLargeOffsetsTerminate) {
  // x far from zero with a tiny span: accumulating x += step would never advance.
  const std::string svg = line_plot({{"s", kBlue, {1e9, 1e9 + 1e-3}, {0.0, 1.0}}}, "t", "x (mm)", "y (µm)");
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("x (mm)"), std::string::npos);
}

TEST(Svg, TextIsEscaped) {
  const std::string svg = line_plot({}, "a < b & c", "x", "y");
  EXPECT_NE(svg.find("a &lt; b &amp; c"), std::string::npos);
  EXPECT_EQ(svg.find("a < b"), std::string::npos);
}

}  // namespace
}  // namespace eical::tools::report
