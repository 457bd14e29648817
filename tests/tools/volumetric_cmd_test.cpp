// `eical volumetric` in-process with the example model: results and refusals.
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"
#include "sim/simulate.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/cli_runner.hpp"
#include "tools/io/volumetric_model_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// A short positioning run of `axis` (two cycles over three targets, strips at the origin).
eical::sim::Scenario short_positioning(const std::string& axis, std::uint64_t seed) {
  auto sc = eical::sim::positioning_scenario({-20, 0, 20}, 2, 2000.0, seed);
  sc.meta.program.axis = axis;
  sc.meta.program.gcode.clear();
  sc.meta.id = "vol-cmd-" + axis;
  eical::dsp::PsdSpec sx, sy;
  sx.measures = "x", sy.measures = "y";
  sc.meta.psd = {sx, sy};
  return sc;
}

fs::path vol_cmd_dir() {
  const fs::path dir = fs::temp_directory_path() / ("vol-cmd-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  return dir;
}

// xtx at +20 mm of a fitted model: value and U.
std::pair<double, double> xtx_at_20(const fs::path& model) {
  const auto f = eical::tools::read_volumetric_model(model.string());
  const auto& c = f.model.component[0];
  return {c.values.back(), f.component[0].u_k2.back()};
}

TEST(VolumetricCmd, FitAppliesTheCalibration) {
  // The sensors' x sensitivity 600 ppm above the data sheet's (both sensors): with the data
  // sheet the run measures x 600 ppm long (12 µm at +20 mm on a perfect machine); the
  // calibration that knows the true sensors takes it out.
  const fs::path dir = vol_cmd_dir();
  auto sc = short_positioning("x", 21);
  for (auto& t : sc.truth) t.spec.k1_v_per_g[0] *= 1.0 + 600e-6;
  eical::drivers::write_run(eical::sim::simulate(sc), dir / "pos-x");
  eical::drivers::SensorCalibration cal;
  cal.run_id = "identify-test";
  for (int s = 0; s < 2; ++s) cal.sensors[s] = sc.truth[s].spec;
  eical::drivers::write_sensor_calibration(cal, dir / "cal.toml");
  run_cli({"volumetric", "--fit", (dir / "pos-x").string(), "-o", (dir / "datasheet.toml").string()});
  run_cli({"volumetric", "--fit", (dir / "pos-x").string(), "--calibration", (dir / "cal.toml").string(), "-o",
           (dir / "calibrated.toml").string()});
  const auto [ds, ds_u] = xtx_at_20(dir / "datasheet.toml");
  const auto [cal_v, cal_u] = xtx_at_20(dir / "calibrated.toml");
  std::printf("xtx(+20 mm), truth 0: data sheet %.2f ± %.2f um, calibrated %.2f ± %.2f um\n", ds, ds_u, cal_v, cal_u);
  EXPECT_GT(ds, 6.0);                              // the scale error the data sheet leaves
  EXPECT_LT(std::abs(cal_v), std::abs(ds) / 3.0);  // the calibration applied
  EXPECT_LE(std::abs(cal_v), cal_u);               // and its U covers the truth
  EXPECT_NE(slurp(dir / "datasheet.toml").find("U from the run's draws"), std::string::npos);
  fs::remove_all(dir);
}

TEST(VolumetricCmd, FitLeavesOutACriticalRunAndNamesIt) {
  const fs::path dir = vol_cmd_dir();
  eical::drivers::write_run(eical::sim::simulate(short_positioning("x", 22)), dir / "pos-x");
  eical::dsp::Run y = eical::sim::simulate(short_positioning("y", 23));
  // The DAQ lost 20 frames (the reader sees the gap in the sample index), none of them a trigger.
  auto at = y.frames.begin() + static_cast<std::ptrdiff_t>(y.frames.size() / 2);
  while (std::any_of(at, at + 20, [](const eical::dsp::Frame& f) { return f.trigger != 0; })) at += 20;
  y.frames.erase(at, at + 20);
  eical::drivers::write_run(y, dir / "pos-y");
  run_cli({"volumetric", "--fit", (dir / "pos-x").string(), (dir / "pos-y").string(), "-o", (dir / "m.toml").string()});
  const std::string model = slurp(dir / "m.toml");
  EXPECT_NE(model.find((dir / "pos-y").string() + ": left out, critical flag: frames_lost"), std::string::npos)
      << model;
  EXPECT_NE(model.find("not measured: no positioning run moves y"), std::string::npos) << model;

  // Nothing usable left: an error naming the run and its reason, and no file.
  try {
    run_cli({"volumetric", "--fit", (dir / "pos-y").string(), "-o", (dir / "none.toml").string()});
    FAIL() << "fitted a model from a run with a critical flag";
  } catch (const eical::dsp::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no usable positioning run"), std::string::npos) << what;
    EXPECT_NE(what.find((dir / "pos-y").string() + ": left out, critical flag: frames_lost"), std::string::npos)
        << what;
  }
  EXPECT_FALSE(fs::exists(dir / "none.toml"));
  fs::remove_all(dir);
}

}  // namespace
