// eical plan's strip layout (issue 33): where each strip goes, in text, JSON and SVG.
#include "tools/plan/strip_layout.hpp"

#include <gtest/gtest.h>

#include <string>

namespace plan = eical::tools::plan;

namespace {

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST(StripLayout, ConfigurationBOfACircleIsPlacedOnItsPath) {
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::circle, p.radius_mm = 50.0;
  p.psd = plan::strips_for(p);
  const auto j = plan::layout_json(p);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["measures"], "x");
  EXPECT_DOUBLE_EQ(j[0]["center_mm"][0].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j[0]["center_mm"][1].get<double>(), -50.0);
  EXPECT_EQ(j[1]["measures"], "y");
  EXPECT_DOUBLE_EQ(j[1]["center_mm"][0].get<double>(), 50.0);
  const std::string t = plan::layout_text(p);
  EXPECT_NE(t.find("strip 1: centre (0.000, -50.000) mm in xy, its length along X"), std::string::npos) << t;
  EXPECT_NE(t.find("strip 2: centre (50.000, 0.000) mm in xy, its length along Y"), std::string::npos) << t;
  const std::string svg = plan::layout_svg(p);
  EXPECT_EQ(count(svg, "<rect "), 2u) << svg;
  EXPECT_EQ(count(svg, "<polyline "), 1u);
  EXPECT_NE(svg.find("strip 2: Y at (50, 0) mm"), std::string::npos) << svg;
}

TEST(StripLayout, APositioningTestGetsItsStripAtMidTravel) {
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::positioning, p.targets_mm = {0.0, 100.0, 200.0, 300.0};
  p.psd = plan::strips_for(p);
  const auto j = plan::layout_json(p);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_DOUBLE_EQ(j[0]["center_mm"][0].get<double>(), 150.0);
  EXPECT_NE(plan::layout_text(p).find("strip 1: centre (150.000, 0.000)"), std::string::npos);
}

TEST(StripLayout, NoStripsIsSaid) {
  plan::TestProgram p;
  EXPECT_NE(plan::layout_text(p).find("no PSD strips"), std::string::npos);
  EXPECT_TRUE(plan::layout_json(p).empty());
  EXPECT_EQ(count(plan::layout_svg(p), "<rect "), 0u);
}
