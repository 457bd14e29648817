// The identification a plan proposes (issue 33): across the test's own strips, every swing
// inside the travel the test moves over, and gen-nc's program says the same.
#include "tools/plan/identification_plan.hpp"
#include "sim/gcode/generate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace plan = eical::tools::plan;
namespace gcode = eical::sim::gcode;

namespace {

// The smallest and largest x and y the program's G0/G1 words reach.
struct Reach {
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
};
Reach reach(const std::string& program) {
  Reach r;
  std::size_t from = 0;
  while (from < program.size()) {
    const std::size_t end = std::min(program.find('\n', from), program.size());
    const std::string line = program.substr(from, end - from);
    from = end + 1;
    if (line.rfind("G0 ", 0) != 0 && line.rfind("G1 ", 0) != 0) continue;
    for (int k = 0; k < 2; ++k) {
      const auto at = line.find(k == 0 ? " X" : " Y");
      if (at == std::string::npos) continue;
      const double v = std::stod(line.substr(at + 2));
      r.lo[k] = std::min(r.lo[k], v), r.hi[k] = std::max(r.hi[k], v);
    }
  }
  return r;
}

}  // namespace

TEST(IdentificationPlan, APositioningTestsIdentificationStaysInsideItsTravel) {
  // The case of issue 33: 0–100 mm swung x from −25 to 125 mm.
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::positioning, p.targets_mm = {0.0, 25.0, 50.0, 75.0, 100.0};
  p.psd = plan::strips_for(p);
  const auto id = plan::identification_plan(p);
  const Reach r = reach(gcode::identify_program(id));
  EXPECT_GE(r.lo[0], 0.0);
  EXPECT_LE(r.hi[0], 100.0);
  EXPECT_NEAR(r.hi[0] - r.lo[0], 50.0, 1e-9) << "the swing keeps its lever";
  EXPECT_NE(plan::identification_command(id).find("--travel x:0,100"), std::string::npos);
}

// Turned radial, a ring's strips sit on the circle's ends (x = ±R measuring x): they stay
// where the circle crosses them, and the swings run on beyond the circle just far enough to
// cross each whole.
TEST(IdentificationPlan, ARadialRingIsReachedBeyondTheCircle) {
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::circle, p.radius_mm = 50.0, p.identified = true;
  p.psd = plan::strips_for(p, 16, eical::sim::StripFacing::across_path);
  EXPECT_EQ(plan::strips_identification_can_cross(p).at(4).center_mm[0], 50.0) << "the strip stays on the circle";
  const auto id = plan::identification_plan(p);
  ASSERT_TRUE(id.travel_mm[0] && id.travel_mm[1]);
  EXPECT_DOUBLE_EQ(id.travel_mm[0]->hi_mm, 56.0);
  EXPECT_DOUBLE_EQ(id.travel_mm[1]->lo_mm, -56.0);
  const Reach r = reach(gcode::identify_program(id));  // accepted: every strip crossed whole
  EXPECT_LE(r.hi[0], 56.0);
  EXPECT_GE(r.hi[0], 55.0);
  // Along the path the circle's own travel suffices: no swing leaves it.
  p.psd = plan::strips_for(p, 16);
  const Reach along = reach(gcode::identify_program(plan::identification_plan(p)));
  EXPECT_LE(along.hi[0], 50.0);
  EXPECT_GE(along.lo[1], -50.0);
}

TEST(IdentificationPlan, StripsAtBothEndsOfATravelAreSwungFromInside) {
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::positioning, p.targets_mm = {0.0, 150.0, 300.0};
  p.psd = plan::strips_at_both_ends(p);
  ASSERT_EQ(p.psd.size(), 2u);
  EXPECT_DOUBLE_EQ(p.psd[0].center_mm[0], 0.0);  // on the ends: the test stands on them
  EXPECT_DOUBLE_EQ(p.psd[1].center_mm[0], 300.0);
  // Identified, one strip length inside each end, where a swing inside the travel crosses.
  p.psd = plan::strips_identification_can_cross(p);
  EXPECT_DOUBLE_EQ(p.psd[0].center_mm[0], 10.0);
  EXPECT_DOUBLE_EQ(p.psd[1].center_mm[0], 290.0);
  const auto id = plan::identification_plan(p);
  const auto a = gcode::strip_swing(id, id.psd[0]), b = gcode::strip_swing(id, id.psd[1]);
  EXPECT_DOUBLE_EQ(a.centre_mm - a.half_mm, 0.0);
  EXPECT_DOUBLE_EQ(b.centre_mm + b.half_mm, 300.0);
  // Each swing carries the spot over its whole strip.
  EXPECT_LE(std::abs(p.psd[0].center_mm[0] - a.centre_mm) + 0.5 * p.psd[0].length_mm, a.half_mm);
  EXPECT_LE(std::abs(p.psd[1].center_mm[0] - b.centre_mm) + 0.5 * p.psd[1].length_mm, b.half_mm);
  const Reach r = reach(gcode::identify_program(id));
  EXPECT_GE(r.lo[0], 0.0);
  EXPECT_LE(r.hi[0], 300.0);
}

// A strip at the very end of the travel cannot be crossed by a swing that stays inside it:
// refused with where it must go, not written as a program whose run identify refuses.
TEST(IdentificationPlan, AStripAtTheEndOfTheTravelIsRefusedWithWhereItMustGo) {
  gcode::IdentifyPlan id;
  id.psd.resize(1);
  id.psd[0].measures = "x", id.psd[0].center_mm[0] = 0.0;
  id.travel_mm[0] = gcode::AxisTravel{0.0, 300.0};
  try {
    (void)gcode::identify_program(id);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("mount it at least 5 mm inside"), std::string::npos) << e.what();
  }
}

TEST(IdentificationPlan, ACirclesIdentificationUsesItsStripsAndRadius) {
  plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::circle, p.radius_mm = 50.0;
  p.psd = plan::strips_for(p);
  const auto id = plan::identification_plan(p);
  ASSERT_EQ(id.psd.size(), 2u);
  EXPECT_DOUBLE_EQ(id.psd[0].center_mm[1], -50.0) << "the test's strips, not R10's";
  const Reach r = reach(gcode::identify_program(id));
  for (int k = 0; k < 2; ++k) {
    EXPECT_GE(r.lo[k], -50.0);
    EXPECT_LE(r.hi[k], 50.0);
  }
  // At R10 the circle spans less than the 50 mm lever: the swing keeps it, centred on the
  // circle.
  p.radius_mm = 10.0, p.psd = plan::strips_for(p);
  const auto small = plan::identification_plan(p);
  EXPECT_DOUBLE_EQ(gcode::strip_swing(small, small.psd[0]).half_mm, 25.0);
  EXPECT_DOUBLE_EQ(gcode::strip_swing(small, small.psd[1]).centre_mm, 0.0);
  const std::string text = plan::identification_text(small);
  EXPECT_NE(text.find("x swings -25 … 25 mm across the strip at y = -10 mm"), std::string::npos) << text;
  const auto j = plan::identification_json(small);
  EXPECT_EQ(j["swings"].size(), 3u);  // x, y and z
  EXPECT_DOUBLE_EQ(j["swings"][1]["to_mm"].get<double>(), 25.0);
}

TEST(IdentificationPlan, AStripOutsideTheTravelIsRefusedByName) {
  gcode::IdentifyPlan id;
  id.psd.resize(1);
  id.psd[0].measures = "x", id.psd[0].center_mm[0] = 120.0;
  id.travel_mm[0] = gcode::AxisTravel{0.0, 100.0};
  try {
    (void)gcode::identify_program(id);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("outside the travel"), std::string::npos) << e.what();
  }
}
