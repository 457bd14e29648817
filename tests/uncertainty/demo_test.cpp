// The main job shows the working instrument: `eical demo` identifies the sensors on site,
// runs the circular test with strips through the daemon's path, and calls it ok, with
// G ± U, U against the noise bound and the truth inside U; its second part calls a test
// beyond the instrument not measurable. Two seeds: two machines, two sets of sensors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>

namespace eical {
namespace {

std::string run_cli(const std::string& args, int& status) {
  FILE* p = ::popen((std::string(EICAL_CLI) + " " + args + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int st = p ? ::pclose(p) : -1;
  status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

class Demo : public ::testing::TestWithParam<int> {};

TEST_P(Demo, ShowsTheWorkingInstrumentThenOneBeyondIt) {
  const auto dir = std::filesystem::temp_directory_path() / ("eical-demo-" + std::to_string(std::random_device{}()));
  int status = -1;
  const std::string out = run_cli("demo --seed " + std::to_string(GetParam()) + " -o " + dir.string(), status);
  std::fputs(out.c_str(), stdout);
  EXPECT_EQ(status, 0) << out;
  const auto part2 = out.find("part 2");
  ASSERT_NE(part2, std::string::npos) << out;
  const std::string one = out.substr(0, part2), two = out.substr(part2);
  EXPECT_NE(one.find("sensors identified on site"), std::string::npos);
  EXPECT_NE(one.find("verdict ok"), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(one, m, std::regex(R"(G = ([0-9.]+) ± ([0-9.]+) µm.*U/bound ([0-9.]+))")));
  const double u = std::stod(m[2]), ratio = std::stod(m[3]);
  EXPECT_LE(u, 10.0);     // what a circular test must resolve
  EXPECT_GE(ratio, 0.9);  // U cannot be below the physics' bound by more than its draws' scatter
  EXPECT_LE(ratio, 2.0);  // and is near it
  EXPECT_NE(one.find("within U"), std::string::npos) << "the truth outside U";
  EXPECT_NE(two.find("verdict not_measurable"), std::string::npos) << two;
  EXPECT_NE(two.find("a circle test is meant to resolve"), std::string::npos) << two;
  // What it wrote: the calibration it identified, and a result that says the same.
  EXPECT_TRUE(std::filesystem::exists(dir / "calibration.toml"));
  std::ifstream in(dir / "result.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["quality"]["verdict"], "ok");
  EXPECT_TRUE(j["sensor_model"]["identified"].get<bool>());
  EXPECT_TRUE(j["noise_bound_k2"]["circle.circular_deviation_G_um"].is_number());
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Seeds, Demo, ::testing::Values(1, 7));

}  // namespace
}  // namespace eical
