// `eical comp`: proposals from measured results, only from resolved figures, outputs that
// merge (one section per joint, the reversal folded into COMP_FILE tables, no file
// overwritten without --force) and a clear error, with nothing written, on bad input.
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/simulate.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::tools::testing::run_cli;

struct Tmp {
  fs::path dir = fs::temp_directory_path() / ("eical-comp-" + std::to_string(std::random_device{}()));
  Tmp() { fs::create_directories(dir); }
  ~Tmp() { fs::remove_all(dir); }
};

using test_support::slurp;

// A positioning result as eical analyze writes it: 5 targets, a lead error of 100 ppm and
// 6 µm play; `u` = the uncertainty_k2 of M and mean B (absent when negative).
nlohmann::json positioning_result(double u, const std::string& axis = "x", double first = -20.0) {
  nlohmann::json per = nlohmann::json::array();
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < 5; ++i) {
    const double x = first + 10.0 * i, pitch = 0.1 * x;  // 100 ppm
    per.push_back({{"target_mm", x}, {"mean_up_um", pitch - 3.0}, {"mean_down_um", pitch + 3.0}});
    lo = std::min(lo, pitch), hi = std::max(hi, pitch);
  }
  nlohmann::json j = {
      {"format", "eical-result/1"},
      {"run_id", "pos-" + axis},
      {"program", "positioning"},
      {"positioning",
       {{"axis", axis}, {"A_um", 12.0}, {"M_um", hi - lo}, {"B_um", -6.0}, {"B_mean_um", -6.0}, {"per_target", per}}}};
  if (u >= 0) j["uncertainty_k2"] = {{"positioning.M_um", u}, {"positioning.B_mean_um", u}};
  return j;
}

// A circle result: backlash x 5 µm, y `backlash_y`, squareness 30 µrad, centre (0, 0), R 10.
nlohmann::json circle_result(double u, double backlash_y = 4.0) {
  nlohmann::json j = {{"format", "eical-result/1"},
                      {"run_id", "circle"},
                      {"program", "circle"},
                      {"circle", {{"plane", "xy"}, {"center_mm", {0.0, 0.0}}, {"radius_nominal_mm", 10.0}}},
                      {"diagnostics",
                       {{"backlash_x_um", 5.0},
                        {"backlash_y_um", backlash_y},
                        {"squareness_urad", 30.0},
                        {"scale_mismatch_ppm", 100.0}}}};
  if (u >= 0)
    j["uncertainty_k2"] = {
        {"diagnostics.backlash_x_um", u}, {"diagnostics.backlash_y_um", u}, {"diagnostics.squareness_urad", 5.0}};
  return j;
}

fs::path write(const fs::path& file, const nlohmann::json& j) {
  std::ofstream(file) << j.dump(2);
  return file;
}

const char* kMachineIni =
    "[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n[TRAJ]\nCOORDINATES = X Y Z\n"
    "[JOINT_0]\nTYPE = LINEAR\nBACKLASH = 0.002\nMAX_VELOCITY = 130\n\n"
    "[JOINT_1]\nTYPE = LINEAR\nBACKLASH = 0.000\n\n[JOINT_2]\nTYPE = LINEAR\n";

TEST(CompCmd, ResolvedFiguresGiveOneSectionPerJointWithTheReversalFoldedIntoTheTable) {
  Tmp t;
  const auto pos = write(t.dir / "pos.json", positioning_result(0.5)),
             circ = write(t.dir / "circle.json", circle_result(0.5));
  std::ofstream(t.dir / "machine.ini") << kMachineIni;
  run_cli({"comp", pos.string(), circ.string(), "-o", (t.dir / "out").string(), "--merge-ini",
           (t.dir / "machine.ini").string(), "--control", "all"});
  // The snippet: one section per joint; x has the table and no BACKLASH, y the circle's backlash.
  const std::string snippet = slurp(t.dir / "out/linuxcnc/eical-comp.ini");
  EXPECT_EQ(snippet.find("[JOINT_0]"), snippet.rfind("[JOINT_0]"));
  EXPECT_NE(snippet.find("COMP_FILE = eical_joint0.comp"), std::string::npos) << snippet;
  EXPECT_NE(snippet.find("BACKLASH = 0.0040000"), std::string::npos) << snippet;  // y from the circle
  const std::string joint0 =
      snippet.substr(snippet.find("[JOINT_0]"), snippet.find("[JOINT_1]") - snippet.find("[JOINT_0]"));
  EXPECT_EQ(joint0.find("\nBACKLASH"), std::string::npos) << joint0;
  // The merged INI: the machine's other keys kept, one [JOINT_0], its BACKLASH set to 0.
  const std::string merged = slurp(t.dir / "out/linuxcnc/machine.ini");
  EXPECT_EQ(merged.find("[JOINT_0]"), merged.rfind("[JOINT_0]"));
  EXPECT_NE(merged.find("MAX_VELOCITY = 130"), std::string::npos);
  EXPECT_NE(merged.find("# eical comp replaced: BACKLASH = 0.002\nBACKLASH = 0.0000000"), std::string::npos) << merged;
  EXPECT_NE(merged.find("COMP_FILE = eical_joint0.comp\nCOMP_FILE_TYPE = 0"), std::string::npos) << merged;
  // The COMP_FILE (type 0): actual = nominal + deviation; the reversal as measured.
  std::ifstream comp(t.dir / "out/linuxcnc/eical_joint0.comp");
  double n = 0, f = 0, r = 0;
  int rows = 0;
  while (comp >> n >> f >> r) {
    EXPECT_NEAR(f, n + (0.1 * n - 3.0) * 1e-3, 1e-7);
    EXPECT_NEAR(r, n + (0.1 * n + 3.0) * 1e-3, 1e-7);
    ++rows;
  }
  EXPECT_EQ(rows, 5);
  // Every control's files, and comp.json naming each figure and what it was used for.
  for (const char* file :
       {"sinumerik/AX_EEC.INI", "sinumerik/backlash.txt", "fanuc/parameters.txt", "fanuc/pitch_error_table.txt",
        "heidenhain/X.COM", "heidenhain/CONFIG.CMA", "heidenhain/backlash.txt"})
    EXPECT_TRUE(fs::exists(t.dir / "out" / file)) << file;
  const auto j = nlohmann::json::parse(slurp(t.dir / "out/comp.json"));
  EXPECT_EQ(j["format"], "eical-comp/1");
  EXPECT_NEAR(j["axes"]["x"]["lost_motion_in_table_um"].get<double>(), 6.0, 1e-9);
  EXPECT_NEAR(j["axes"]["y"]["lost_motion_um"].get<double>(), 4.0, 1e-9);
  EXPECT_FALSE(j.contains("proposed_from_unresolved_figures"));
  EXPECT_EQ(j["not_compensated"].size(), 2u);  // squareness and scale mismatch
}

TEST(CompCmd, NeverOverwritesWithoutForce) {
  Tmp t;
  const auto pos = write(t.dir / "pos.json", positioning_result(0.5));
  run_cli({"comp", pos.string(), "-o", (t.dir / "out").string()});
  const std::string first = slurp(t.dir / "out/linuxcnc/eical_joint0.comp");
  // A second proposal for the same axis: refused, nothing touched.
  const auto pos2 = write(t.dir / "pos2.json", positioning_result(0.5, "x", -10.0));
  try {
    run_cli({"comp", pos2.string(), "-o", (t.dir / "out").string()});
    FAIL() << "overwrote without --force";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("would overwrite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("eical_joint0.comp"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(t.dir / "out/linuxcnc/eical_joint0.comp"), first);
  run_cli({"comp", pos2.string(), "-o", (t.dir / "out").string(), "--force"});
  EXPECT_NE(slurp(t.dir / "out/linuxcnc/eical_joint0.comp"), first);
  // Two positioning runs of one axis in one call: which table is meant is not guessed.
  EXPECT_THROW(run_cli({"comp", pos.string(), pos2.string(), "-o", (t.dir / "out2").string()}), eical::dsp::InputError);
  EXPECT_FALSE(fs::exists(t.dir / "out2"));
}

TEST(CompCmd, UnresolvedFiguresAreLeftOutByDefaultAndRefusedWhenAsked) {
  Tmp t;
  const auto pos = write(t.dir / "pos.json", positioning_result(0.5));
  const auto circ = write(t.dir / "circle.json", circle_result(0.5, 0.3));  // backlash y 0.3 ± 0.5 µm
  const auto bare = write(t.dir / "bare.json", positioning_result(-1.0));   // no uncertainty_k2 at all
  const std::string out = (t.dir / "out").string();
  // --refuse-unresolved: nothing is written while one term is not resolved.
  try {
    run_cli({"comp", pos.string(), circ.string(), "-o", out, "--refuse-unresolved"});
    FAIL() << "proposed from an unresolved figure";
  } catch (const eical::dsp::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("diagnostics.backlash_y_um = 0.3 (U = 0.5, k = 2)"), std::string::npos) << m;
    EXPECT_NE(m.find("nothing written"), std::string::npos) << m;
    EXPECT_EQ(m.find("positioning.M_um"), std::string::npos) << m;  // resolved ones are not named
  }
  EXPECT_FALSE(fs::exists(out));
  // Nothing resolved at all: refused by default too, each figure named.
  try {
    run_cli({"comp", bare.string(), "-o", out});
    FAIL() << "proposed from figures without an uncertainty";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no term is resolved"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("positioning.M_um = 4 (no uncertainty)"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
  // The default (as --skip-unresolved): y is left out and listed, x proposed.
  for (const char* flag : {"", "--skip-unresolved"}) {
    const std::string o = out + flag;
    std::vector<std::string> args{"comp", pos.string(), circ.string(), "-o", o};
    if (*flag) args.emplace_back(flag);
    run_cli(args);
    const std::string snippet = slurp(fs::path(o) / "linuxcnc/eical-comp.ini");
    EXPECT_NE(snippet.find("[JOINT_0]"), std::string::npos);
    EXPECT_EQ(snippet.find("[JOINT_1]"), std::string::npos) << snippet;
    const auto left = nlohmann::json::parse(slurp(fs::path(o) / "comp.json"));
    ASSERT_TRUE(left.contains("left_out_unresolved_figures")) << "what was left out is said";
    ASSERT_EQ(left["left_out_unresolved_figures"].size(), 1u);
    EXPECT_NE(left["left_out_unresolved_figures"][0].get<std::string>().find("diagnostics.backlash_y_um"),
              std::string::npos);
  }
  // --allow-unresolved: proposed and said so in comp.json.
  run_cli({"comp", bare.string(), "-o", (t.dir / "out3").string(), "--allow-unresolved"});
  const auto j = nlohmann::json::parse(slurp(t.dir / "out3/comp.json"));
  ASSERT_TRUE(j.contains("proposed_from_unresolved_figures"));
  EXPECT_EQ(j["proposed_from_unresolved_figures"].size(), 2u);
}

TEST(CompCmd, ATableThatDoesNotCoverTheMeasuredTravelIsRefused) {
  Tmp t;
  const auto pos = write(t.dir / "pos.json", positioning_result(0.5, "x", 0.0));  // 0 .. 40 mm
  const auto circ = write(t.dir / "circle.json", circle_result(0.5));             // x -10 .. 10 mm
  try {
    run_cli({"comp", pos.string(), circ.string(), "-o", (t.dir / "out").string()});
    FAIL() << "accepted a table that does not cover the circle";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the x table covers 0 .. 40 mm, but circle run"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(t.dir / "out"));
  EXPECT_THROW(run_cli({"comp", pos.string(), "--travel", "x:0,100", "-o", (t.dir / "out").string()}),
               eical::dsp::InputError);
  EXPECT_FALSE(fs::exists(t.dir / "out"));
}

TEST(CompCmd, RunDirectoriesAreAnalysedAndTheirProgramNamesTheTravel) {
  Tmp t;
  eical::drivers::write_run(eical::sim::simulate(eical::sim::positioning_scenario({-12, 0, 12}, 2)), t.dir / "pos");
  eical::drivers::write_run(eical::sim::simulate(eical::sim::circle_scenario(10, 2500, 2)), t.dir / "circle");
  // No uncertainty_k2 in today's results: refused without the override.
  EXPECT_THROW(run_cli({"comp", (t.dir / "pos").string(), (t.dir / "circle").string(), "-o", (t.dir / "out").string()}),
               eical::dsp::InputError);
  run_cli({"comp", (t.dir / "pos").string(), (t.dir / "circle").string(), "-o", (t.dir / "out").string(),
           "--allow-unresolved"});
  const auto j = nlohmann::json::parse(slurp(t.dir / "out/comp.json"));
  EXPECT_EQ(j["axes"]["x"]["table"].size(), 3u);
  EXPECT_TRUE(fs::exists(t.dir / "out/linuxcnc/eical_joint0.comp"));
}

TEST(CompCmd, NotAResultIsAClearError) {
  Tmp t;
  std::ofstream(t.dir / "x.json") << "{\"format\": \"eical-explain/1\"}";
  try {
    run_cli({"comp", (t.dir / "x.json").string(), "-o", (t.dir / "out").string()});
    FAIL();
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not an eical-result/1 document"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run_cli({"comp", (t.dir / "missing").string()}), eical::dsp::InputError);
}

}  // namespace
