#include "sim/gcode/parser.hpp"

#include "dsp/core/error.hpp"

#include <gtest/gtest.h>
#include <numbers>

#include <cmath>
#include <string>

namespace eical::sim::gcode {
namespace {

// The circle program of the sample runs (tests/data/baseline-0011/run.toml).
constexpr const char* kCircle = R"(G90 G21 G17 G64 (continuous path: the arcs are one blended move)
G0 X7.0711 Y7.0711
G4 P0.4
M101
G4 P0.1
G3 X-7.0711 Y7.0711 I-7.0711 J-7.0711 F2500 (ramp-in)
M102
G3 X-7.0711 Y7.0711 I7.0711 J-7.0711
M102
G3 X-7.0711 Y-7.0711 I7.0711 J-7.0711 (ramp-out)
G4 P0.4
M103
)";

std::string error_of(const std::string& text) {
  try {
    parse(text, "t.ngc");
  } catch (const dsp::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(GcodeParser, SampleCircleProgramBlocks) {
  const Program p = parse(kCircle, "circle.ngc");
  ASSERT_EQ(p.blocks.size(), 11u);
  EXPECT_FALSE(p.exact_stop);
  const auto& rapid = std::get<Linear>(p.blocks[0]);
  EXPECT_TRUE(rapid.rapid);
  EXPECT_NEAR(rapid.to_mm.x(), 7.0711, 1e-12);
  EXPECT_NEAR(std::get<Dwell>(p.blocks[1]).duration_s, 0.4, 1e-12);
  EXPECT_EQ(std::get<Trigger>(p.blocks[2]).code, 101);
  EXPECT_TRUE(std::isnan(std::get<Trigger>(p.blocks[2]).p));
  const auto& ramp_in = std::get<Arc>(p.blocks[4]);
  EXPECT_FALSE(ramp_in.clockwise);
  EXPECT_NEAR(ramp_in.sweep_rad, std::numbers::pi / 2.0, 1e-4);
  EXPECT_NEAR(ramp_in.center_mm.norm(), 0.0, 1e-4);
  EXPECT_DOUBLE_EQ(ramp_in.feed_mm_min, 2500.0);
  const auto& full = std::get<Arc>(p.blocks[6]);
  EXPECT_NEAR(full.sweep_rad, 2.0 * std::numbers::pi, 1e-12) << "same start and end point is a full turn";
  const auto& ramp_out = std::get<Arc>(p.blocks[8]);
  EXPECT_NEAR(ramp_out.sweep_rad, std::numbers::pi / 2.0, 1e-4);
  EXPECT_EQ(p.source[8].line, 10);
  EXPECT_EQ(std::get<Trigger>(p.blocks[10]).code, 103);
}

TEST(GcodeParser, RFormArcsPickShortOrLongArc) {
  // Quarter circle of radius 10 from (10,0) to (0,10), counter-clockwise.
  const Program shortp = parse("G17 G3 X0 Y10 R10 F1000", "t", {.start_mm = {10, 0, 0}});
  const auto& a = std::get<Arc>(shortp.blocks[0]);
  EXPECT_NEAR(a.center_mm.x(), 0.0, 1e-9);
  EXPECT_NEAR(a.center_mm.y(), 0.0, 1e-9);
  EXPECT_NEAR(a.sweep_rad, std::numbers::pi / 2.0, 1e-9);
  // Negative R: the long way round (270°) about the mirrored centre.
  const Program longp = parse("G3 X0 Y10 R-10 F1000", "t", {.start_mm = {10, 0, 0}});
  const auto& b = std::get<Arc>(longp.blocks[0]);
  EXPECT_NEAR(b.center_mm.x(), 10.0, 1e-9);
  EXPECT_NEAR(b.center_mm.y(), 10.0, 1e-9);
  EXPECT_NEAR(b.sweep_rad, 1.5 * std::numbers::pi, 1e-9);
  // Clockwise short arc: centre on the other side.
  const Program cw = parse("G2 X0 Y10 R10 F1000", "t", {.start_mm = {10, 0, 0}});
  const auto& c = std::get<Arc>(cw.blocks[0]);
  EXPECT_NEAR(c.center_mm.x(), 10.0, 1e-9);
  EXPECT_NEAR(c.center_mm.y(), 10.0, 1e-9);
  EXPECT_NEAR(c.sweep_rad, -std::numbers::pi / 2.0, 1e-9);
}

TEST(GcodeParser, PlanesUnitsAndIncrementalMode) {
  // G18 (ZX plane): offsets I (x) and K (z); G20 inches; G91 incremental.
  const Program p = parse("G20 G91 G18\nG2 X1 Z1 I1 K0 F10\nG1 Y-1\nG21 G90 G1 X0 Y0 Z0 F100", "t");
  ASSERT_EQ(p.blocks.size(), 3u);
  const auto& arc = std::get<Arc>(p.blocks[0]);
  EXPECT_EQ(arc.plane, Plane::zx);
  EXPECT_NEAR(arc.to_mm.x(), 25.4, 1e-12);
  EXPECT_NEAR(arc.to_mm.z(), 25.4, 1e-12);
  EXPECT_NEAR(arc.center_mm.x(), 25.4, 1e-12);
  EXPECT_DOUBLE_EQ(arc.feed_mm_min, 254.0);
  const auto& lin = std::get<Linear>(p.blocks[1]);
  EXPECT_NEAR(lin.to_mm.y(), -25.4, 1e-12);
  EXPECT_NEAR(std::get<Linear>(p.blocks[2]).to_mm.norm(), 0.0, 1e-12);
}

TEST(GcodeParser, TriggerCarriesPAndQWords) {
  const Program p = parse("M101 P3 Q0.5", "t");
  const auto& t = std::get<Trigger>(p.blocks[0]);
  EXPECT_EQ(t.code, 101);
  EXPECT_DOUBLE_EQ(t.p, 3.0);
  EXPECT_DOUBLE_EQ(t.q, 0.5);
}

TEST(GcodeParser, ErrorsNameLineAndColumn) {
  EXPECT_EQ(error_of("G1 X1 F100\nG1 X2 W5"), "t.ngc:2:7: unsupported word 'W'");
  EXPECT_EQ(error_of("G1 X1 F100\n\nG5 X1"), "t.ngc:3:1: unsupported G-code G5");
  EXPECT_EQ(error_of("M62"), "t.ngc:1:1: unsupported M-code M62");
  EXPECT_NE(error_of("G1 X1").find("t.ngc:1:1: G1 without a feed rate F"), std::string::npos);
  EXPECT_NE(error_of("G4").find("G4 needs P"), std::string::npos);
  EXPECT_NE(error_of("G1 X1 F100 (open comment").find("t.ngc:1:12: comment"), std::string::npos);
  EXPECT_NE(error_of("G3 X20 Y0 R5 F100").find("smaller than half the chord"), std::string::npos);
  EXPECT_NE(error_of("G3 X1 Y0 I5 J0 F100").find("not on the circle"), std::string::npos);
  EXPECT_NE(error_of("G1 X1 X2 F100").find("appears twice"), std::string::npos);
  EXPECT_NE(error_of("X5").find("without a motion mode"), std::string::npos);
  EXPECT_NE(error_of("G1 X=5").find("needs a number"), std::string::npos);
}

// A real part program as a CAM post-processor writes it for a FANUC, run as a free-form test.
TEST(GcodeParser, RealPartProgramsAreRead) {
  const char* text =
      "%\n"
      "O1000 (POCKET 40X20)\n"
      "N10 G17 G21 G40 G49 G80 G90 G94 G54 ; safety line\n"
      "N20 T1 M6 (D10 END MILL)\n"
      "N30 S8000 M3\n"
      "N40 M8\n"
      "N50 G0 X-20. Y-10.\n"
      "/N55 M1\n"
      "N60 G1 X20. F1200\n"
      "N70 G3 X20. Y10. I0. J10.\n"
      "n80 g1 x-20. (lower case, as some posts write)\n"
      "N90 G0 Z50. M9\n"
      "N100 M5\n"
      "N110 M30\n"
      "%\n";
  const Program p = parse(text, "pocket.nc", {.dialect = Dialect::fanuc});
  ASSERT_EQ(p.blocks.size(), 5u);  // G0, G1, G3, G1, G0: M-codes, S and T add nothing to the path
  const auto& first = std::get<Linear>(p.blocks[0]);
  EXPECT_TRUE(first.rapid);
  EXPECT_NEAR(first.to_mm.x(), -20.0, 1e-12);
  const auto& arc = std::get<Arc>(p.blocks[2]);
  EXPECT_FALSE(arc.clockwise);
  EXPECT_NEAR(arc.center_mm.y(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(std::get<Linear>(p.blocks[3]).feed_mm_min, 1200.0);
}

TEST(GcodeParser, PartProgramsStillRefuseWhatTheyCannotSimulate) {
  EXPECT_EQ(error_of("%\nN10 G81 X1 Y1 Z-2 R1 F100"), "t.ngc:2:5: unsupported G-code G81");  // canned cycle
  EXPECT_EQ(error_of("G0 X0\nG43 H1 Z50"), "t.ngc:2:5: unsupported word 'H'");               // tool length offset
  EXPECT_EQ(error_of("G28"), "t.ngc:1:1: unsupported G-code G28");
  EXPECT_EQ(error_of("G55"), "t.ngc:1:1: unsupported G-code G55");
  EXPECT_NE(error_of("o100 sub").find("t.ngc:1:6: O-word control flow"), std::string::npos) << error_of("o100 sub");
  EXPECT_EQ(error_of("G1 X1 F100\n#1 = 2"), "t.ngc:2:1: expected a word letter, got '#'");
}

}  // namespace eical::sim::gcode
