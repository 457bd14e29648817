// `eical gen-nc` run in-process: options reach the generator and the files are written.
#include "sim/gcode/parser.hpp"
#include "tools/commands.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

std::string run_to_file(std::vector<std::string> args, const fs::path& out) {
  CLI::App app;
  eical::tools::register_all(app);
  args.insert(args.begin(), "eical");
  args.push_back("--out");
  args.push_back(out.string());
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  app.parse(static_cast<int>(argv.size()), argv.data());
  std::ifstream is(out);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

TEST(GenNc, EachKindKeepsItsOwnDefaultsAndOptions) {
  const fs::path out = fs::temp_directory_path() / ("gen-nc-" + std::to_string(std::random_device{}()) + ".ngc");
  const std::string circle = run_to_file({"gen-nc", "circle", "--radius", "25", "--direction", "cw"}, out);
  EXPECT_NE(circle.find("F2500"), std::string::npos) << circle;  // circle's own default feed
  EXPECT_NE(circle.find("G2 "), std::string::npos);
  const auto prog = eical::sim::gcode::parse(circle);
  int arcs = 0;
  for (const auto& b : prog.blocks)
    if (const auto* arc = std::get_if<eical::sim::gcode::Arc>(&b)) {
      EXPECT_NEAR((arc->from_mm - arc->center_mm).norm(), 25.0, 1e-3);
      EXPECT_TRUE(arc->clockwise);
      ++arcs;
    }
  EXPECT_EQ(arcs, 5 + 2);  // default repeats, ramp-in and ramp-out

  const std::string pos = run_to_file({"gen-nc", "positioning", "--targets", "0,10,20", "--runs", "3"}, out);
  EXPECT_NE(pos.find("F2000"), std::string::npos);
  std::size_t n102 = 0;
  for (std::size_t i = pos.find("M102"); i != std::string::npos; i = pos.find("M102", i + 1)) ++n102;
  EXPECT_EQ(n102, 3u * 2u * 3u);
  fs::remove(out);
}

TEST(GenNc, InvalidOptionIsAParseError) {
  CLI::App app;
  eical::tools::register_all(app);
  const char* argv[] = {"eical", "gen-nc", "circle", "--plane", "xz"};
  EXPECT_THROW(app.parse(5, argv), CLI::ValidationError);
}

}  // namespace

namespace {

// A 220° partial arc in the YZ plane, both directions: G19, ramp / arc / ramp each way,
// M102 around each evaluated arc only, and the [program] table carries the arc.
TEST(GenNc, PartialArcBothDirectionsInAnyPlane) {
  const fs::path out = fs::temp_directory_path() / ("gen-nc-arc-" + std::to_string(std::random_device{}()) + ".ngc");
  const fs::path meta = out.string() + ".toml";
  const std::string g = run_to_file({"gen-nc", "circle", "--plane", "yz", "--arc-deg", "220", "--direction", "both",
                                     "--radius", "15", "--center", "0,40", "--repeats", "1", "--meta", meta.string()},
                                    out);
  EXPECT_NE(g.find("G19"), std::string::npos) << g;
  const auto prog = eical::sim::gcode::parse(g);
  std::vector<double> sweeps_deg;
  for (const auto& b : prog.blocks)
    if (const auto* arc = std::get_if<eical::sim::gcode::Arc>(&b)) {
      EXPECT_EQ(arc->plane, eical::sim::gcode::Plane::yz);
      EXPECT_NEAR((arc->from_mm - arc->center_mm).norm(), 15.0, 1e-3);
      EXPECT_NEAR(arc->center_mm.z(), 40.0, 1e-9);
      sweeps_deg.push_back(arc->sweep_rad * 180.0 / 3.14159265358979323846);
    }
  ASSERT_EQ(sweeps_deg.size(), 6u);  // ramp-in, arc, ramp-out; and back
  EXPECT_NEAR(sweeps_deg[1], 220.0, 1e-3);
  EXPECT_NEAR(sweeps_deg[4], -220.0, 1e-3);
  EXPECT_NEAR(sweeps_deg[0], 45.0, 1e-3);  // min(45°, (360° − 220°)/2)
  // M102 right before and after each evaluated arc.
  std::vector<int> order;  // 0 = arc block, 1 = M102
  for (const auto& b : prog.blocks) {
    if (std::holds_alternative<eical::sim::gcode::Arc>(b)) order.push_back(0);
    if (const auto* t = std::get_if<eical::sim::gcode::Trigger>(&b); t && t->code == 102) order.push_back(1);
  }
  const std::vector<int> expected{0, 1, 0, 1, 0, 0, 1, 0, 1, 0};
  EXPECT_EQ(order, expected);
  std::ifstream is(meta);
  const std::string toml{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
  EXPECT_NE(toml.find("arc_deg = 220"), std::string::npos) << toml;
  EXPECT_NE(toml.find("arc_start_deg = -20"), std::string::npos) << toml;
  EXPECT_NE(toml.find("direction = \"both\""), std::string::npos) << toml;
  fs::remove(out);
  fs::remove(meta);
}

TEST(GenNc, PartialArcWithoutRoomForTheRampsIsRefused) {
  const fs::path out = fs::temp_directory_path() / ("gen-nc-arc-" + std::to_string(std::random_device{}()) + ".ngc");
  try {
    (void)run_to_file({"gen-nc", "circle", "--arc-deg", "350"}, out);
    FAIL() << "350 deg partial arc accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("arc_deg <= 340"), std::string::npos) << e.what();
  }
  fs::remove(out);
}

}  // namespace
