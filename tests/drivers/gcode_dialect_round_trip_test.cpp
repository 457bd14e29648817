// Acceptance of issue 32: every program `eical gen-nc` writes (the generators and the
// dialect writer it calls), in every dialect, read back the way `eical simulate --scenario
// S --dialect D` reads a [program] gcode_file, runs the same path (within 1 µm) with the
// same dwells (within 1 ms) and takes the same time as the LinuxCNC program. Prints the
// worst differences per dialect and program.
#include "drivers/config/scenario_file.hpp"
#include "sim/gcode/dialect.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/gcode/parser.hpp"
#include "sim/nc/trajectory.hpp"
#include "tests/support/gcode_compare.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::sim::gcode::Dialect;

// gen-nc's programs: every kind, circles both ways and partial in every plane.
struct Case {
  std::string name;
  std::function<std::string()> canonical;
};

std::vector<Case> every_program() {
  namespace g = eical::sim::gcode;
  std::vector<Case> cases;
  for (const char* plane : {"xy", "zx", "yz"})
    for (const char* dir : {"ccw", "cw", "both"})
      for (double arc : {360.0, 220.0}) {
        eical::dsp::Program p;
        p.kind = eical::dsp::ProgramKind::circle, p.plane = plane, p.direction = dir, p.arc_deg = arc, p.repeats = 2;
        p.radius_mm = 25.0, p.center_mm[0] = 5.0, p.center_mm[1] = -5.0, p.feed_mm_min = 2500.0;
        cases.push_back({std::string("circle ") + plane + " " + dir + " " + std::to_string(static_cast<int>(arc)),
                         [p] { return g::circle_program(p); }});
      }
  eical::dsp::Program pos;
  pos.kind = eical::dsp::ProgramKind::positioning, pos.axis = "x", pos.targets_mm = {0.0, 12.5, 25.0, 50.0},
  pos.runs = 2;
  pos.feed_mm_min = 2000.0, pos.dwell_s = 0.25;
  cases.push_back({"positioning", [pos] { return g::positioning_program(pos, 2.0); }});
  eical::dsp::Program step;
  step.kind = eical::dsp::ProgramKind::step, step.axis = "y", step.targets_mm = {0.0, 50.0}, step.runs = 2,
  step.feed_mm_min = 3250.0;
  step.dwell_s = 0.5;
  cases.push_back({"step", [step] { return g::step_program(step); }});
  for (const char* plane : {"xy", "zx", "yz"}) {
    eical::dsp::Program r;
    r.kind = eical::dsp::ProgramKind::rectangle, r.plane = plane, r.size_mm[0] = 40.0, r.size_mm[1] = 20.0,
    r.feed_mm_min = 1000.0;
    r.dwell_s = 0.2, r.repeats = 1;
    cases.push_back({std::string("rectangle ") + plane, [r] { return g::rectangle_program(r); }});
  }
  g::IdentifyPlan plan;
  eical::dsp::PsdSpec sx, sy;
  sx.measures = "x", sx.center_mm[0] = 0.0, sx.center_mm[1] = -10.0;
  sy.measures = "y", sy.center_mm[0] = 10.0, sy.center_mm[1] = 0.0;
  plan.psd = {sx, sy};
  plan.axes = {"z"};
  cases.push_back({"identify", [plan] { return g::identify_program(plan); }});
  return cases;
}

// The program as simulate reads it: a scenario naming the file, read in its dialect.
eical::dsp::Program read_as_simulate(const fs::path& dir, const fs::path& nc, Dialect d) {
  const fs::path scenario = dir / "scenario.toml";
  std::ofstream(scenario) << "format = \"eical-scenario/1\"\n[program]\nkind = \"freeform\"\ngcode_file = \""
                          << nc.filename().string() << "\"\n";
  return eical::drivers::read_scenario_file(scenario.string(), d).meta.program;
}

}  // namespace

TEST(GcodeDialectRoundTrip, EveryGenNcProgramInEveryDialect) {
  const fs::path dir = fs::temp_directory_path() / ("gcode-rt-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  const eical::sim::nc::MachineLimits limits;
  for (const Case& c : every_program()) {
    const std::string canonical = c.canonical();
    const eical::sim::gcode::ProgramIdentity id{1000, "EICAL_TEST", c.name};  // as gen-nc's write_program
    const std::string lcnc = eical::sim::gcode::write_dialect(canonical, Dialect::linuxcnc, id);
    const auto ref = eical::sim::nc::interpolate_gcode(lcnc, "linuxcnc", limits);
    const Eigen::Vector3d start = ref.at(0.0).pos_mm;
    const auto want = eical::sim::gcode::parse(lcnc, "linuxcnc", {.start_mm = start});
    for (Dialect d : {Dialect::linuxcnc, Dialect::fanuc, Dialect::sinumerik, Dialect::heidenhain_iso}) {
      const std::string dialect = eical::sim::gcode::dialect_name(d);
      const fs::path nc = dir / (dialect + ".nc");
      const std::string text = eical::sim::gcode::write_dialect(canonical, d, id);
      std::ofstream(nc) << text;
      SCOPED_TRACE(c.name + ", " + dialect + ":\n" + text);
      eical::dsp::Program kept;
      ASSERT_NO_THROW(kept = read_as_simulate(dir, nc, d));
      const auto got = eical::sim::gcode::parse(kept.gcode, "kept", {.start_mm = start});
      const eical::test::ProgramDifference diff = eical::test::compare_programs(want, got);
      EXPECT_EQ(diff.mismatch, "");
      EXPECT_LE(diff.path_um, 1.0);
      EXPECT_LE(diff.dwell_ms, 1.0);
      // The same run in time: the set-point the simulator makes of both.
      const auto run = eical::sim::nc::interpolate_gcode(kept.gcode, "kept", limits);
      const double dt_ms = 1e3 * std::abs(run.duration_s() - ref.duration_s());
      double worst_um = 0.0;
      for (double t = 0.0; t <= ref.duration_s(); t += 0.005)
        worst_um = std::max(worst_um, 1e3 * (run.at(t).pos_mm - ref.at(t).pos_mm).norm());
      EXPECT_LE(dt_ms, 1.0);
      EXPECT_LE(worst_um, 1.0);
      std::printf("%-22s %-14s path %.4f um  dwell %.4f ms  run %.3f s (%+.4f ms)  set-point %.4f um\n", c.name.c_str(),
                  dialect.c_str(), diff.path_um, diff.dwell_ms, run.duration_s(),
                  1e3 * (run.duration_s() - ref.duration_s()), worst_um);
    }
  }
  fs::remove_all(dir);
}

TEST(GcodeDialectRoundTrip, SimulateNamesTheUsersFileAndRefusesAnEmptyOne) {
  const fs::path dir = fs::temp_directory_path() / ("gcode-rt-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  auto error_of = [&](const std::string& text, Dialect d) -> std::string {
    std::ofstream(dir / "user.nc") << text;
    try {
      (void)read_as_simulate(dir, dir / "user.nc", d);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  const std::string file = (dir / "user.nc").string();
  EXPECT_EQ(error_of("G0 X1\nG1 X2 F100 W3\n", Dialect::linuxcnc), file + ":2:12: unsupported word 'W'");
  EXPECT_NE(error_of("", Dialect::linuxcnc).find(file + ": the program has no motion"), std::string::npos);
  EXPECT_NE(error_of("%\nO1000\nG04 P400\n%\n", Dialect::fanuc).find(file + ": the program has no motion"),
            std::string::npos);
  fs::remove_all(dir);
}
