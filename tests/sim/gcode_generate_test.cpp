#include "dsp/core/error.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/gcode/parser.hpp"
#include "tests/support/sample_data.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

namespace eical::sim::gcode {
namespace {

int count_triggers(const Program& prog, int code) {
  int n = 0;
  for (const auto& b : prog.blocks)
    if (const auto* t = std::get_if<Trigger>(&b); t && t->code == code) ++n;
  return n;
}

// The G-code stored in a recorded run's run.toml (between gcode = """ and """).
std::string recorded_gcode(const std::string& run) {
  const auto path = test::committed_data() / run / "run.toml";
  std::ifstream is(path);
  const std::string text{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
  const auto a = text.find("gcode = \"\"\"\n");
  if (a == std::string::npos) return {};
  const auto b = text.find("\"\"\"", a + 12);
  return text.substr(a + 12, b - a - 12);
}

dsp::Program circle() {
  dsp::Program p;
  p.kind = eical::dsp::ProgramKind::circle;
  p.radius_mm = 10.0;
  p.feed_mm_min = 2500.0;
  p.repeats = 5;
  return p;
}

TEST(GcodeGenerate, CircleMatchesTheRecordedRunsProgram) {
  const std::string recorded = recorded_gcode("baseline-0011");
  ASSERT_FALSE(recorded.empty()) << "no G-code in " << test::committed_data() / "baseline-0011/run.toml";
  EXPECT_EQ(circle_program(circle()), recorded);
}

TEST(GcodeGenerate, StepMatchesTheRecordedRunsProgram) {
  const std::string recorded = recorded_gcode("baseline.step-0011");
  ASSERT_FALSE(recorded.empty()) << "no G-code in " << test::committed_data() / "baseline.step-0011/run.toml";
  dsp::Program p;
  p.kind = eical::dsp::ProgramKind::step;
  p.axis = "x";
  p.targets_mm = {0.0, 50.0};
  p.feed_mm_min = 3250.0;
  p.runs = 2;
  p.dwell_s = 0.5;
  // The recorded run stood at the first target; the program now approaches it first.
  std::string program = step_program(p);
  const std::string approach = "G0 X0.0000 (approach)\n";
  const auto at = program.find(approach);
  ASSERT_NE(at, std::string::npos) << program;
  EXPECT_LT(at, program.find("M101"));
  program.erase(at, approach.size());
  EXPECT_EQ(program, recorded);
}

TEST(GcodeGenerate, CircleInEveryPlaneAndDirectionParsesToTheRightSweep) {
  for (const char* plane : {"xy", "zx", "yz"})
    for (const char* dir : {"ccw", "cw"}) {
      auto p = circle();
      p.plane = plane;
      p.direction = dir;
      p.repeats = 3;
      const Program prog = parse(circle_program(p), "circle.ngc");
      double sweep = 0.0;
      for (const auto& b : prog.blocks)
        if (const auto* a = std::get_if<Arc>(&b)) {
          sweep += a->sweep_rad;
          EXPECT_EQ(a->clockwise, std::string(dir) == "cw");
        }
      const double expected = (3 * 2 + 1) * std::numbers::pi * (std::string(dir) == "cw" ? -1 : 1);
      EXPECT_NEAR(sweep, expected, 1e-6) << plane << " " << dir;
      EXPECT_EQ(count_triggers(prog, 101), 1);
      EXPECT_EQ(count_triggers(prog, 102), 4);  // one before each revolution, one after the last
      EXPECT_EQ(count_triggers(prog, 103), 1);
      EXPECT_FALSE(prog.exact_stop);
    }
}

TEST(GcodeGenerate, PositioningVisitsEveryTargetInBothDirectionsEachRun) {
  dsp::Program p;
  p.kind = eical::dsp::ProgramKind::positioning;
  p.axis = "y";
  p.targets_mm = {0.0, 10.0, 25.0, 40.0};
  p.runs = 5;
  p.feed_mm_min = 2000.0;
  const Program prog = parse(positioning_program(p, 2.0), "pos.ngc", {});
  EXPECT_EQ(count_triggers(prog, 102), 5 * 2 * 4);
  // Each M102 follows a move that ends at a target, and the approach direction alternates
  // up (4 targets) / down (4 targets) per run.
  int k = 0;
  for (std::size_t i = 1; i < prog.blocks.size(); ++i) {
    const auto* t = std::get_if<Trigger>(&prog.blocks[i]);
    if (!t || t->code != 102) continue;
    const auto& mv = std::get<Linear>(prog.blocks[i - 1]);
    const bool up = (k / 4) % 2 == 0;
    EXPECT_EQ(mv.to_mm.y() > mv.from_mm.y(), up) << "trigger " << k;
    const double target =
        up ? p.targets_mm[static_cast<std::size_t>(k % 4)] : p.targets_mm[3 - static_cast<std::size_t>(k % 4)];
    EXPECT_NEAR(mv.to_mm.y(), target, 1e-9);
    ++k;
  }
  EXPECT_TRUE(prog.exact_stop);
}

TEST(GcodeGenerate, RectangleAndIdentifyParse) {
  dsp::Program r;
  r.kind = eical::dsp::ProgramKind::rectangle;
  r.size_mm[0] = 20;
  r.size_mm[1] = 10;
  r.repeats = 2;
  EXPECT_EQ(count_triggers(parse(program_gcode(r)), 102), 8);
  dsp::Program id;
  id.kind = eical::dsp::ProgramKind::identify;
  id.targets_mm = {25.0};
  EXPECT_EQ(count_triggers(parse(program_gcode(id)), 102), 6);  // three feeds, both ways
  // Two strips and z: 6 swings each, a transfer to the second strip, z out, 6, back.
  IdentifyPlan plan;
  plan.psd.resize(2);
  plan.psd[0].measures = "x", plan.psd[0].center_mm[1] = -10.0;
  plan.psd[1].measures = "y", plan.psd[1].center_mm[0] = 10.0;
  plan.axes = {"z"};
  const auto prog = parse(identify_program(plan));
  EXPECT_EQ(count_triggers(prog, 102), 6 + 1 + 6 + 1 + 6 + 1);
  plan.psd[0].measures = "z";
  plan.psd.resize(1);
  EXPECT_THROW((void)identify_program(plan), dsp::InputError);
}

TEST(GcodeGenerate, IncompleteProgramsAreRefused) {
  dsp::Program p = circle();
  p.radius_mm = -1;
  EXPECT_THROW((void)circle_program(p), dsp::InputError);
  p = circle();
  p.plane = "xz";
  EXPECT_THROW((void)circle_program(p), dsp::InputError);
  dsp::Program pos;
  pos.kind = eical::dsp::ProgramKind::positioning;
  pos.targets_mm = {10, 0};
  EXPECT_THROW((void)program_gcode(pos), dsp::InputError);
  pos.kind = eical::dsp::ProgramKind::freeform;  // a contour is the user's own NC
  EXPECT_THROW((void)program_gcode(pos), dsp::InputError);
}

}  // namespace
}  // namespace eical::sim::gcode
