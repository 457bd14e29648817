// The circular test's report section (issue 33): a polar plot per direction, and a trace
// whose U(G) exceeds the range it spans drawn as the band of that U with a note, not as a
// shape the reader would take for the machine's.
#include "tools/report/sections.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

namespace eical::tools::report {
namespace {

namespace fs = std::filesystem;

// One revolution per direction: a 2 µm ellipse, and G with the given U per direction.
dsp::Analysis analysis(double u_ccw_um, double u_cw_um) {
  dsp::Analysis a;
  a.circle = dsp::eval::CircleResult{};
  auto& c = *a.circle;
  c.direction = "both", c.revolutions = 0;
  for (const char* dir : {"ccw", "cw"})
    for (int i = 0; i < 360; ++i) {
      c.trace.angle_deg.push_back(i);
      c.trace.radius_deviation_um.push_back(std::cos(2.0 * i * 3.14159265358979 / 180.0));
      c.trace.direction.emplace_back(dir);
      c.trace.revolution.push_back(0);
    }
  c.circular_deviation_G_um = 2.0;
  c.direction_F_max_um = {1.0, 1.0}, c.direction_F_min_um = {-1.0, -1.0};
  a.uncertainty_k2["circle.circular_deviation_G_um"] = {std::max(u_ccw_um, u_cw_um)};
  a.uncertainty_k2["circle.circular_deviation_G_ccw_um"] = {u_ccw_um};
  a.uncertainty_k2["circle.circular_deviation_G_cw_um"] = {u_cw_um};
  return a;
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

Page page_of(const dsp::Analysis& a) {
  dsp::Run run;
  run.meta.program.kind = eical::dsp::ProgramKind::circle, run.meta.program.radius_mm = 100.0,
  run.meta.program.feed_mm_min = 4000.0;
  const fs::path dir = fs::temp_directory_path() / ("eical-circle-section-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  CsvFiles csv(dir);
  Page page;
  circle_sections(run, a, page, csv);
  fs::remove_all(dir);
  return page;
}

TEST(CircleSection, EachDirectionHasItsOwnPlot) {
  const Page page = page_of(analysis(0.5, 0.6));
  ASSERT_EQ(page.sections.size(), 1u);
  const auto& svgs = page.sections[0].svgs;
  ASSERT_EQ(svgs.size(), 2u);
  EXPECT_NE(svgs[0].find("counter-clockwise (G3)"), std::string::npos);
  EXPECT_NE(svgs[1].find("clockwise (G2)"), std::string::npos);
  EXPECT_EQ(svgs[1].find("counter-clockwise"), std::string::npos) << "the cw plot holds ccw";
  for (const auto& svg : svgs) EXPECT_EQ(count(svg, "fill-rule='evenodd'"), 0u) << "a band where U is small";
}

TEST(CircleSection, ATraceBeyondItsUIsDrawnAsABandWithANote) {
  // ccw: U(G) = 876 µm over a trace spanning ±1 µm (R150 without strips); cw resolved.
  const Page page = page_of(analysis(876.0, 0.6));
  const auto& s = page.sections.at(0);
  ASSERT_EQ(s.svgs.size(), 2u);
  EXPECT_EQ(count(s.svgs[0], "fill-rule='evenodd'"), 1u);
  EXPECT_EQ(count(s.svgs[0], "<polyline"), 0u) << "the shape is drawn although U exceeds it";
  EXPECT_NE(s.svgs[0].find("shape not resolved"), std::string::npos);
  EXPECT_EQ(count(s.svgs[1], "fill-rule='evenodd'"), 0u);
  EXPECT_GT(count(s.svgs[1], "<polyline"), 0u);
  bool noted = false;
  for (const auto& n : s.notes) noted = noted || n.find("U(G) = 876.0 µm exceeds the whole range") != std::string::npos;
  EXPECT_TRUE(noted) << "no note says why the ccw plot is a band";
}

}  // namespace
}  // namespace eical::tools::report
