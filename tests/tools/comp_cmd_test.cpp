// `eical comp` on simulated runs: the proposal files exist and hold what the runs gave.
#include "drivers/run_io/run_writer.hpp"
#include "sim/simulate.hpp"
#include "tools/commands.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

TEST(CompCmd, ProposesTablesFromPositioningAndTermsFromCircles) {
  const fs::path dir = fs::temp_directory_path() / ("comp-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  eical::drivers::write_run(eical::sim::simulate(eical::sim::positioning_scenario({0, 25, 50}, 2)), dir / "pos");
  eical::drivers::write_run(eical::sim::simulate(eical::sim::circle_scenario(10, 2500, 2)), dir / "circle");
  CLI::App app;
  eical::tools::register_all(app);
  const std::string a = (dir / "pos").string(), b = (dir / "circle").string(), out = (dir / "out").string();
  const char* argv[] = {"eical", "comp", a.c_str(), b.c_str(), "-o", out.c_str()};
  app.parse(6, argv);
  std::ifstream js(dir / "out" / "comp.json");
  const auto j = nlohmann::json::parse(js);
  ASSERT_TRUE(j.contains("positioning"));
  ASSERT_TRUE(j.contains("circle"));
  const auto& table = j["positioning"].begin().value()["table"];
  EXPECT_EQ(table.size(), 3u);
  std::ifstream comp(dir / "out" / "axis_x.comp");
  std::string header;
  std::getline(comp, header);
  double n = 0, f = 0, r = 0;
  int rows = 0;
  while (comp >> n >> f >> r) {
    // forward/reverse = nominal − deviation; the table's deviations are micrometres.
    EXPECT_NEAR(f, n - table[static_cast<std::size_t>(rows)]["forward_deviation_um"].get<double>() / 1000.0, 1e-6);
    ++rows;
  }
  EXPECT_EQ(rows, 3);
  std::ifstream ini(dir / "out" / "linuxcnc.ini");
  const std::string text{std::istreambuf_iterator<char>(ini), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find("COMP_FILE = axis_x.comp"), std::string::npos);
  EXPECT_NE(text.find("BACKLASH"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
