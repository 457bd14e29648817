// The SVG plots: scales that cover the data (and always terminate), escaped text.
#include "tools/report/svg.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

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

// The points of the first polyline of `svg`.
std::vector<std::pair<double, double>> first_polyline(const std::string& svg) {
  std::smatch m;
  std::vector<std::pair<double, double>> pts;
  if (!std::regex_search(svg, m, std::regex("<polyline[^>]*points='([^']*)'"))) return pts;
  std::istringstream is(m[1].str());
  double x = 0, y = 0;
  char comma = 0;
  while (is >> x >> comma >> y) pts.emplace_back(x, y);
  return pts;
}

TEST(Svg, ARevolutionIsDrawnAsMeasuredNotJoinedToItsStart) {
  // Integration drift opens a revolution: it ends 3 µm off where it began. Joining the two
  // would draw a hook the machine does not have (issue 33).
  std::vector<double> ang, dev;
  for (int i = 0; i < 360; ++i) ang.push_back(i), dev.push_back(3.0 * i / 359.0);
  PolarTrace t{"rev 1", kBlue, ang, dev, true};
  const auto pts = first_polyline(polar_plot({t}, "t"));
  ASSERT_EQ(pts.size(), ang.size()) << "one point per sample, none added to close it";
  EXPECT_GT(std::hypot(pts.front().first - pts.back().first, pts.front().second - pts.back().second), 5.0);
}

TEST(Svg, APolarBandReplacesTheShapeAndSetsTheScale) {
  const std::string svg = polar_plot({}, "t", "+X", "+Y", 0.0, "G 233 ± 876 µm", {438.0, kRed, "± U(G)/2"});
  EXPECT_NE(svg.find("fill-rule='evenodd'"), std::string::npos) << "no band drawn";
  EXPECT_NE(svg.find("± U(G)/2"), std::string::npos) << "the band is not in the legend";
  EXPECT_EQ(svg.find("<polyline"), std::string::npos);
  const auto at = svg.find(" µm / division");
  const auto from = svg.rfind('>', at) + 1;
  EXPECT_GE(3.0 * std::stod(svg.substr(from, at - from)), 438.0) << "the band does not fit the rings";
}

TEST(Svg, ALinePlotsLegendLiesUnderItsFrame) {
  std::vector<LineSeries> series;
  for (int k = 0; k < 4; ++k) series.push_back({"series " + std::to_string(k), kBlue, {0.0, 1.0}, {0.0, 1.0 + k}});
  const std::string svg = line_plot(series, "t", "x (mm)", "y (µm)", 680, 300);
  std::smatch frame;
  ASSERT_TRUE(std::regex_search(svg, frame,
                                std::regex("<rect x='[^']*' y='([^']*)' width='[^']*' height='([^']*)' "
                                           "fill='none'")));
  const double frame_bottom = std::stod(frame[1].str()) + std::stod(frame[2].str());
  for (int k = 0; k < 4; ++k) {
    std::smatch m;
    ASSERT_TRUE(std::regex_search(svg, m, std::regex("<text x='[^']*' y='([^']*)'[^>]*>series " + std::to_string(k))));
    EXPECT_GT(std::stod(m[1].str()), frame_bottom + 20.0) << "legend entry " << k << " inside the frame";
  }
  std::smatch size;
  ASSERT_TRUE(std::regex_search(svg, size, std::regex("height='([0-9.]+)'")));
  EXPECT_GT(std::stod(size[1].str()), 300.0) << "the legend's rows add to the height";
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
