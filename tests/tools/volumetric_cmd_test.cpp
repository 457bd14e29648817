// `eical volumetric` in-process with the example model: results and refusals.
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/simulate.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/cli_runner.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;
const fs::path kModel = fs::path(EICAL_SOURCE_DIR) / "config" / "examples" / "volumetric-example.toml";

using eical::tools::testing::run_cli;

using test_support::slurp;

TEST(VolumetricCmd, ExampleModelGivesDeviationsAndFlagsRanges) {
  const fs::path dir = fs::temp_directory_path() / ("vol-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  std::ofstream(dir / "p.csv") << "x,y,z,xp,yp,zp\n0,0,0,0,0,0\n400,250,200,0,0,100\n-1,0,0,0,0,0\n0,0,401,0,0,0\n";
  run_cli({"volumetric", "--model", kModel.string(), "--points", (dir / "p.csv").string(), "--out",
           (dir / "o.csv").string()});
  const std::string out = slurp(dir / "o.csv");
  EXPECT_NE(out.find(",ok\n"), std::string::npos) << out;
  EXPECT_NE(out.find("out_of_range:x"), std::string::npos) << out;
  EXPECT_NE(out.find("out_of_range:z"), std::string::npos) << out;

  // A model with a component missing is refused and no output is written.
  std::string model = slurp(kModel);
  const auto at = model.find("name = \"yrz\"");
  ASSERT_NE(at, std::string::npos);
  model.replace(at, 12, "name = \"yrq\"");
  std::ofstream(dir / "bad.toml") << model;
  fs::remove(dir / "o.csv");
  try {
    run_cli({"volumetric", "--model", (dir / "bad.toml").string(), "--points", (dir / "p.csv").string(), "--out",
             (dir / "o.csv").string()});
    FAIL() << "accepted an unknown component";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("yrq"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "o.csv"));
  fs::remove_all(dir);
}

TEST(VolumetricCmd, FitWithoutAPositioningRunIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("vol-" + std::to_string(std::random_device{}()));
  eical::drivers::write_run(eical::sim::simulate(eical::sim::circle_scenario(10, 2500, 1)), dir / "circle");
  try {
    run_cli({"volumetric", "--fit", (dir / "circle").string(), "-o", (dir / "m.toml").string()});
    FAIL() << "fitted a model without a positioning run";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no positioning run"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "m.toml"));
  fs::remove_all(dir);
}

}  // namespace
