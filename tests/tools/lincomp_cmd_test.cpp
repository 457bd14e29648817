// `eical lincomp` in-process: exports written on success, nothing written on bad input.
#include "dsp/core/error.hpp"
#include "tests/tools/cli_runner.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

struct Tmp {
  fs::path dir = fs::temp_directory_path() / ("eical-lincomp-" + std::to_string(std::random_device{}()));
  Tmp() { fs::create_directories(dir); }
  ~Tmp() { fs::remove_all(dir); }
};

using eical::tools::testing::run_cli;

TEST(LinCompCmd, WritesLinuxCncAndCsvTables) {
  Tmp t;
  {
    std::ofstream os(t.dir / "c.csv");
    os << "pos_mm,error_um\n";
    for (int i = 0; i <= 200; ++i) os << i << "," << 0.02 * i << "\n";  // 20 µm/m
  }
  run_cli({"lincomp", "--curve", (t.dir / "c.csv").string(), "--spacing-mm", "50", "--linuxcnc",
           (t.dir / "x.comp").string(), "--csv", (t.dir / "x.csv").string()});
  // COMP_FILE_TYPE 0 (LinuxCNC usrmotLoadComp): "nominal actual-moving-up actual-moving-down",
  // data from the first line (a comment above it would stop LinuxCNC reading).
  std::ifstream is(t.dir / "x.comp");
  std::vector<std::array<double, 3>> rows;
  double n, f, r;
  while (is >> n >> f >> r) rows.push_back({n, f, r});
  ASSERT_EQ(rows.size(), 5u);  // 0, 50, 100, 150, 200
  // At 200 mm the axis goes 4 µm too far: it arrives at 200.004 mm, so LinuxCNC's trim
  // (nominal − actual) commands 4 µm less.
  EXPECT_NEAR(rows[4][0], 200.0, 1e-9);
  EXPECT_NEAR(rows[4][1], 200.0 + 0.004, 1e-9);
  EXPECT_NEAR(rows[4][2], 200.0 + 0.004, 1e-9);
  // The CSV in the same convention: deviation +4 µm, correction −4 µm.
  std::ifstream csv(t.dir / "x.csv");
  std::string header, line, last;
  std::getline(csv, header);
  EXPECT_EQ(header, "pos_mm,deviation_um,correction_um,correction_up_um,correction_down_um");
  while (std::getline(csv, line)) last = line;
  EXPECT_EQ(last, "200.0000,4.0000,-4.0000,-4.0000,-4.0000");
  EXPECT_TRUE(fs::exists(t.dir / "x.csv"));
  // A second run does not replace the tables without --force, and writes neither file.
  const auto before = fs::last_write_time(t.dir / "x.comp");
  try {
    run_cli({"lincomp", "--curve", (t.dir / "c.csv").string(), "--spacing-mm", "25", "--linuxcnc",
             (t.dir / "x.comp").string(), "--csv", (t.dir / "x.csv").string()});
    FAIL() << "overwrote x.comp without --force";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::last_write_time(t.dir / "x.comp"), before);
  run_cli({"lincomp", "--curve", (t.dir / "c.csv").string(), "--spacing-mm", "25", "--linuxcnc",
           (t.dir / "x.comp").string(), "--force"});
  std::ifstream again(t.dir / "x.comp");
  std::size_t n_rows = 0;
  while (again >> n >> f >> r) ++n_rows;
  EXPECT_EQ(n_rows, 9u);  // 0, 25, ..., 200
}

TEST(LinCompCmd, ACurveThatDoesNotCoverTheTravelWritesNothing) {
  Tmp t;
  std::ofstream(t.dir / "c.csv") << "pos_mm,error_um\n0,0\n50,1\n100,2\n";
  try {
    run_cli({"lincomp", "--curve", (t.dir / "c.csv").string(), "--spacing-mm", "50", "--travel-mm", "0,300",
             "--linuxcnc", (t.dir / "x.comp").string()});
    FAIL() << "accepted a table over 0..100 mm for a 0..300 mm travel";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("covers 0 .. 100 mm"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(t.dir / "x.comp"));
}

TEST(LinCompCmd, BadCurveWritesNothing) {
  Tmp t;
  std::ofstream(t.dir / "bad.csv") << "pos_mm,error_um\n0,1\n10,2\n10,3\n20,4\n";
  EXPECT_THROW(run_cli({"lincomp", "--curve", (t.dir / "bad.csv").string(), "--spacing-mm", "5", "--linuxcnc",
                        (t.dir / "x.comp").string()}),
               eical::dsp::InputError);
  EXPECT_FALSE(fs::exists(t.dir / "x.comp"));
  std::ofstream(t.dir / "nan.csv") << "pos_mm,error_um\n0,1\n10,nan\n20,4\n";
  try {
    run_cli({"lincomp", "--curve", (t.dir / "nan.csv").string(), "--spacing-mm", "5"});
    FAIL();
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nan.csv:3: column 'error_um'"), std::string::npos) << e.what();
  }
}

}  // namespace
