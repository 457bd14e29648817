// ISO 230-2 from outside data: both readers agree, the real runs obey the standard's
// inequalities, bad tables are refused with the line.
#include "dsp/core/error.hpp"
#include "dsp/eval/positioning.hpp"
#include "tests/support/sample_data.hpp"
#include "tools/io/positioning_readers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::dsp::eval::evaluate_positioning;

const fs::path kDir = eical::test::committed_data() / "external" / "iso230-2";

TEST(Iso2302Inputs, EcmcAndDeviationCsvGiveTheSameFigures) {
  ASSERT_TRUE(fs::is_directory(kDir)) << "no ISO 230-2 runs at " << kDir << " (tests/data is part of the repo)";
  int files = 0;
  for (const auto& e : fs::directory_iterator(kDir)) {
    if (e.path().extension() != ".dat") continue;
    ++files;
    const auto a = eical::tools::read_ecmc_dat(e.path().string());
    // The same data as a deviation table, rows shuffled.
    std::vector<std::string> rows;
    char line[128];
    for (std::size_t j = 0; j < a.up_um.size(); ++j)
      for (std::size_t i = 0; i < a.targets_mm.size(); ++i) {
        std::snprintf(line, sizeof line, "%.6f,%zu,up,%.12g", a.targets_mm[i], j + 1, a.up_um[j][i]);
        rows.emplace_back(line);
        std::snprintf(line, sizeof line, "%.6f,%zu,down,%.12g", a.targets_mm[i], j + 1, a.down_um[j][i]);
        rows.emplace_back(line);
      }
    std::shuffle(rows.begin(), rows.end(), std::mt19937_64(1));
    const fs::path csv = fs::temp_directory_path() / ("dev-" + std::to_string(std::random_device{}()) + ".csv");
    {
      std::ofstream os(csv);
      os << "target_mm,run,direction,deviation_um\n";
      for (const auto& r : rows) os << r << "\n";
    }
    const auto b = eical::tools::read_deviation_csv(csv.string());
    fs::remove(csv);
    const auto ra = evaluate_positioning(a), rb = evaluate_positioning(b);
    EXPECT_NEAR(ra.A_um, rb.A_um, 1e-6) << e.path();
    EXPECT_NEAR(ra.R_um, rb.R_um, 1e-6) << e.path();
    EXPECT_NEAR(ra.E_um, rb.E_um, 1e-6) << e.path();
    EXPECT_NEAR(ra.B_mean_um, rb.B_mean_um, 1e-6) << e.path();
    // Inequalities that follow from the definitions.
    EXPECT_GE(ra.A_um + 1e-12, ra.E_um) << e.path();
    EXPECT_GE(ra.E_um + 1e-12, ra.M_um) << e.path();
    EXPECT_GE(ra.R_um + 1e-12, std::max(ra.R_up_um, ra.R_down_um)) << e.path();
    EXPECT_GE(ra.B_um + 1e-12, std::abs(ra.B_mean_um)) << e.path();
    EXPECT_GE(ra.A_um + 1e-12, std::max(ra.A_up_um, ra.A_down_um)) << e.path();
    EXPECT_EQ(ra.runs, 5);
    std::printf("%s: A %.3f E %.3f M %.3f R %.3f B %.3f um\n", e.path().filename().c_str(), ra.A_um, ra.E_um, ra.M_um,
                ra.R_um, ra.B_um);
  }
  EXPECT_EQ(files, 4) << kDir;
}

TEST(Iso2302Inputs, BadTablesAreRefusedWithTheLine) {
  const fs::path csv = fs::temp_directory_path() / ("bad-" + std::to_string(std::random_device{}()) + ".csv");
  auto error = [&](const std::string& text) -> std::string {
    std::ofstream(csv, std::ios::trunc) << text;
    try {
      (void)evaluate_positioning(eical::tools::read_deviation_csv(csv.string()));
    } catch (const eical::dsp::InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string h = "target_mm,run,direction,deviation_um\n";
  EXPECT_NE(error(h + "0,1,up,1\n0,1,sideways,1\n").find(":3: column 'direction'"), std::string::npos);
  EXPECT_NE(error(h + "0,1,up,nan\n").find("column 'deviation_um'"), std::string::npos);
  EXPECT_NE(error(h + "0,1,up,1\n0,1,down,1\n10,1,up,1\n10,1,down,1\n").find("at least 2 runs"), std::string::npos);
  EXPECT_NE(error(h + "0,1,up,1\n0,1,down,1\n0,2,up,1\n0,2,down,1\n10,1,up,1\n10,1,down,1\n10,2,up,1\n")
                .find("no deviation for target 10"),
            std::string::npos);
  fs::remove(csv);
}

}  // namespace
