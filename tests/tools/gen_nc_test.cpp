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
