// `eical gen-nc` run in-process: options reach the generator and the files are written.
#include "sim/gcode/parser.hpp"
#include "tests/support/gcode_compare.hpp"
#include "tools/commands.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
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

namespace {

namespace fs = std::filesystem;

std::string gen(std::vector<std::string> args) {
  const fs::path out = fs::temp_directory_path() / ("gen-nc-d-" + std::to_string(std::random_device{}()) + ".nc");
  const std::string text = run_to_file(std::move(args), out);
  fs::remove(out);
  return text;
}

// Each dialect's program start, dwell unit and end; the approach before the first
// measured motion; and the exact text against golden files (EICAL_UPDATE_GOLDEN=1
// rewrites them).
TEST(GenNc, DialectsHaveTheirDwellUnitsProgramNumbersAndEndCodes) {
  const std::string lcnc = gen({"gen-nc", "step", "--targets", "10,60", "--runs", "1"});
  EXPECT_NE(lcnc.find("G0 X10.0000 (approach)\nG4 P0.4\nM101"), std::string::npos) << lcnc;
  EXPECT_EQ(lcnc.substr(lcnc.size() - 3), "M2\n");
  // What eical simulates: the approach, then the step from the first target.
  const auto prog = eical::sim::gcode::parse(lcnc);
  const auto& approach = std::get<eical::sim::gcode::Linear>(prog.blocks.front());
  EXPECT_TRUE(approach.rapid);
  EXPECT_NEAR(approach.to_mm.x(), 10.0, 1e-12);

  const std::string fanuc =
      gen({"gen-nc", "step", "--targets", "10,60", "--runs", "1", "--dialect", "fanuc", "--program-number", "4711"});
  EXPECT_EQ(fanuc.rfind("%\nO4711 (EICAL STEP", 0), 0u) << fanuc;
  EXPECT_NE(fanuc.find("G04 P400\nM101\nG04 P100"), std::string::npos) << fanuc;  // milliseconds
  EXPECT_EQ(fanuc.substr(fanuc.size() - 6), "M30\n%\n");

  const std::string sin = gen({"gen-nc", "step", "--targets", "10,60", "--runs", "1", "--dialect", "sinumerik"});
  EXPECT_EQ(sin.rfind("%_N_EICAL_STEP_MPF\n;$PATH=/_N_MPF_DIR\n", 0), 0u) << sin;
  EXPECT_NE(sin.find("G90 G71 G17 G60 ; absolute"), std::string::npos) << sin;
  EXPECT_NE(sin.find("G4 F0.400\nM101"), std::string::npos) << sin;  // seconds
  EXPECT_EQ(sin.substr(sin.size() - 4), "M30\n");

  const std::string tnc = gen({"gen-nc", "circle", "--repeats", "1", "--center", "5,0", "--dialect", "heidenhain-iso",
                               "--program-name", "CAL1"});
  EXPECT_EQ(tnc.rfind("%CAL1 G71 *\n", 0), 0u) << tnc;
  EXPECT_NE(tnc.find("G04 F0.400 *\nN40 M101 *"), std::string::npos) << tnc;
  EXPECT_NE(tnc.find(" I+5.0000 J+0.0000 *\nN70 G03 X-2.0711 Y+7.0711 F2500 *"), std::string::npos)
      << tnc;  // absolute centre
  const std::string tnc_end = "\nN99999999 %CAL1 G71 *\n";
  EXPECT_EQ(tnc.substr(tnc.size() - tnc_end.size()), tnc_end);

  const fs::path golden = fs::path(EICAL_SOURCE_DIR) / "tests/tools/golden/gen-nc";
  const bool update = std::getenv("EICAL_UPDATE_GOLDEN") && std::string(std::getenv("EICAL_UPDATE_GOLDEN")) == "1";
  for (const char* d : {"linuxcnc", "fanuc", "sinumerik", "heidenhain-iso"})
    for (const char* kind : {"circle", "positioning"}) {
      std::vector<std::string> args = {"gen-nc", kind, "--dialect", d};
      if (std::string(kind) == "circle")
        args.insert(args.end(), {"--repeats", "1", "--direction", "both"});
      else
        args.insert(args.end(), {"--targets", "0,10", "--runs", "1"});
      const std::string text = gen(args);
      const fs::path p = golden / (std::string(d) + "-" + kind + ".nc");
      if (update) {
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        continue;
      }
      std::ifstream is(p, std::ios::binary);
      ASSERT_TRUE(is) << p;
      EXPECT_EQ(text, std::string(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>())) << p;
    }
}

// Issue 32: every program gen-nc writes, in each control's dialect, read back by the reader
// simulate and the free-form test use, is the LinuxCNC program: paths within 1 µm, dwells
// within 1 ms, the same blocks, feeds and triggers.
TEST(GenNc, EveryProgramInEveryDialectReadsBackAsTheSameProgram) {
  using eical::sim::gcode::Dialect;
  const fs::path out = fs::temp_directory_path() / ("gen-nc-rt-" + std::to_string(std::random_device{}()) + ".nc");
  const std::vector<std::vector<std::string>> programs = {
      {"circle", "--repeats", "2", "--direction", "both"},
      {"circle", "--radius", "50", "--arc-deg", "200", "--plane", "zx"},
      {"positioning", "--targets", "0,12.5,25,50", "--runs", "2", "--dwell", "0.75"},
      {"step", "--targets", "0,40", "--dwell", "0.3"},
      {"rectangle", "--size", "40,30", "--dwell", "0.2"},
      {"identify", "--psd", "x:0,-10", "--psd", "y:10,0", "--axis", "z"}};
  const std::pair<Dialect, const char*> dialects[] = {
      {Dialect::fanuc, "fanuc"}, {Dialect::sinumerik, "sinumerik"}, {Dialect::heidenhain_iso, "heidenhain-iso"}};
  double worst_path_um[3] = {}, worst_dwell_ms[3] = {};
  for (const auto& program : programs) {
    std::vector<std::string> args{"gen-nc"};
    args.insert(args.end(), program.begin(), program.end());
    const auto want = eical::sim::gcode::parse(run_to_file(args, out), "linuxcnc");
    for (int i = 0; i < 3; ++i) {
      std::vector<std::string> a = args;
      a.insert(a.end(), {"--dialect", dialects[i].second});
      const std::string text = run_to_file(a, out);
      SCOPED_TRACE(std::string(dialects[i].second) + " " + program.front() + ":\n" + text);
      eical::sim::gcode::Program got;
      ASSERT_NO_THROW(got = eical::sim::gcode::parse(text, "written", {.dialect = dialects[i].first}));
      const auto diff = eical::test::compare_programs(want, got);
      EXPECT_EQ(diff.mismatch, "");
      EXPECT_LE(diff.path_um, 1.0);
      EXPECT_LE(diff.dwell_ms, 1.0);
      worst_path_um[i] = std::max(worst_path_um[i], diff.path_um);
      worst_dwell_ms[i] = std::max(worst_dwell_ms[i], diff.dwell_ms);
    }
  }
  fs::remove(out);
  for (int i = 0; i < 3; ++i)
    std::printf("gen-nc, every program, %-14s worst path %.4f um, worst dwell %.4f ms\n", dialects[i].second,
                worst_path_um[i], worst_dwell_ms[i]);
}

TEST(GenNc, AnUnknownDialectIsRefused) {
  CLI::App app;
  eical::tools::register_all(app);
  const char* argv[] = {"eical", "gen-nc", "circle", "--dialect", "haas"};
  EXPECT_THROW(app.parse(5, argv), CLI::ValidationError);
}

}  // namespace

namespace {

// --travel keeps identify's swings where the test moves (issue 33); a travel that is not
// AXIS:LO,HI with LO < HI is refused by name.
TEST(GenNc, IdentifyStaysInsideTheTravelItIsGiven) {
  const fs::path out = fs::temp_directory_path() / ("gen-nc-id-" + std::to_string(std::random_device{}()) + ".ngc");
  const std::string g =
      run_to_file({"gen-nc", "identify", "--psd", "x:10,0", "--travel", "x:0,100", "--axis", "z"}, out);
  const auto prog = eical::sim::gcode::parse(g);
  double lo = 1e300, hi = -1e300;
  for (const auto& b : prog.blocks)
    if (const auto* m = std::get_if<eical::sim::gcode::Linear>(&b))
      lo = std::min(lo, m->to_mm.x()), hi = std::max(hi, m->to_mm.x());
  EXPECT_GE(lo, 0.0) << g;
  EXPECT_LE(hi, 100.0) << g;
  EXPECT_NEAR(hi - lo, 50.0, 1e-6);
  fs::remove(out);
  for (const char* bad : {"x:100,0", "w:0,1", "x:0,ten"}) {
    try {
      (void)run_to_file({"gen-nc", "identify", "--psd", "x:0,0", "--travel", bad}, out);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("--travel '") + bad + "'"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
