// Each control's own syntax read back: dwell words and units, inch/metric codes, block
// numbers and ends, comments, "%" lines; a word of another control is refused by name.
#include "dsp/core/error.hpp"
#include "sim/gcode/canonical.hpp"
#include "sim/gcode/parser.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace eical::sim::gcode {
namespace {

Program read(const std::string& text, Dialect d) { return parse(text, "user.nc", {.dialect = d}); }

std::string error_of(const std::string& text, Dialect d) {
  try {
    read(text, d);
  } catch (const dsp::InputError& e) {
    return e.what();
  }
  return "";
}

double dwell_s(const Program& p, std::size_t i) { return std::get<Dwell>(p.blocks.at(i)).duration_s; }
const Linear& linear(const Program& p, std::size_t i) { return std::get<Linear>(p.blocks.at(i)); }

}  // namespace

TEST(GcodeDialectRead, DwellWordsAndUnits) {
  EXPECT_DOUBLE_EQ(dwell_s(read("G4 P0.4", Dialect::linuxcnc), 0), 0.4);
  const Program fanuc = read("G04 P400\nG04 X1.5\nG4 P1", Dialect::fanuc);
  EXPECT_DOUBLE_EQ(dwell_s(fanuc, 0), 0.4) << "FANUC P counts milliseconds";
  EXPECT_DOUBLE_EQ(dwell_s(fanuc, 1), 1.5) << "FANUC X counts seconds";
  EXPECT_DOUBLE_EQ(dwell_s(fanuc, 2), 0.001);
  const Program sin = read("G4 F0.4\nS600 M3\nG4 S5\nG1 X1 F100\nG4 F2\nG1 X2", Dialect::sinumerik);
  EXPECT_DOUBLE_EQ(dwell_s(sin, 0), 0.4);
  EXPECT_DOUBLE_EQ(dwell_s(sin, 1), 0.5) << "5 revolutions at 600 rpm";
  EXPECT_DOUBLE_EQ(linear(sin, 4).feed_mm_min, 100.0) << "the F of a G4 block is the dwell, not the feed";
  EXPECT_DOUBLE_EQ(dwell_s(read("N10 G04 F0.250 *", Dialect::heidenhain_iso), 0), 0.25);
}

TEST(GcodeDialectRead, DwellOfAnotherControlIsRefusedByName) {
  EXPECT_NE(error_of("G04 P0.4", Dialect::fanuc).find("FANUC's G04 P counts milliseconds"), std::string::npos);
  EXPECT_NE(error_of("G4 F0.4", Dialect::linuxcnc).find("G4 F<seconds> is SINUMERIK's and HEIDENHAIN ISO's"),
            std::string::npos);
  EXPECT_NE(error_of("G4 P400", Dialect::sinumerik).find("G4 P is LinuxCNC's dwell in seconds, FANUC's in"),
            std::string::npos);
  EXPECT_NE(error_of("G04 X1.", Dialect::linuxcnc).find("G04 X<seconds> is FANUC's dwell"), std::string::npos);
  EXPECT_NE(error_of("G4 S5", Dialect::sinumerik).find("the spindle must turn"), std::string::npos);
  EXPECT_NE(error_of("S600 M3\nM5\nG4 S5", Dialect::sinumerik).find("user.nc:3:4:"), std::string::npos);
  EXPECT_NE(error_of("G4 F-1", Dialect::sinumerik).find("dwell must not be negative"), std::string::npos);
}

TEST(GcodeDialectRead, InchAndMetric) {
  EXPECT_DOUBLE_EQ(linear(read("G20 G1 X1 F10", Dialect::linuxcnc), 0).to_mm.x(), 25.4);
  EXPECT_DOUBLE_EQ(linear(read("G20 G1 X1 F10", Dialect::linuxcnc), 0).feed_mm_min, 254.0);
  EXPECT_DOUBLE_EQ(linear(read("G20 G1 X1. F10", Dialect::fanuc), 0).feed_mm_min, 254.0);
  // SINUMERIK G70 scales lengths only, G700 also the feed; G71/G710 back to mm.
  const Program s = read("G70 G1 X1 F100\nG700 G1 X2 F10\nG71 G1 X3\nG710 G1 X4 F50", Dialect::sinumerik);
  EXPECT_DOUBLE_EQ(linear(s, 0).to_mm.x(), 25.4);
  EXPECT_DOUBLE_EQ(linear(s, 0).feed_mm_min, 100.0);
  EXPECT_DOUBLE_EQ(linear(s, 1).to_mm.x(), 50.8);
  EXPECT_DOUBLE_EQ(linear(s, 1).feed_mm_min, 254.0);
  EXPECT_DOUBLE_EQ(linear(s, 2).to_mm.x(), 3.0);
  EXPECT_DOUBLE_EQ(linear(s, 3).feed_mm_min, 50.0);
  const Program h = read("%P G70 *\nN10 G01 X+1 F10 *\nN99999999 %P G70 *", Dialect::heidenhain_iso);
  EXPECT_DOUBLE_EQ(linear(h, 0).to_mm.x(), 25.4);
  // The metric code of one control is another's cycle: the message says whose it is.
  EXPECT_EQ(error_of("G71", Dialect::linuxcnc),
            "user.nc:1:1: unsupported G-code G71: SINUMERIK and HEIDENHAIN ISO mean metric by it; this file is read "
            "as LinuxCNC (choose the control with --dialect)");
  EXPECT_NE(error_of("G21", Dialect::sinumerik).find("LinuxCNC and FANUC mean metric by it"), std::string::npos);
  EXPECT_NE(error_of("G61", Dialect::heidenhain_iso).find("mean exact stop by it"), std::string::npos);
  // A feed within the word's range in inch/min but beyond it in mm/min is refused where
  // it is read (fuzz finding of gcode_fanuc: its canonical text did not read back).
  EXPECT_NE(error_of("G20 G1 X10. F100010050", Dialect::fanuc)
                .find("user.nc:1:13: feed F is out of range (2540255270 mm/min)"),
            std::string::npos)
      << error_of("G20 G1 X10. F100010050", Dialect::fanuc);
}

TEST(GcodeDialectRead, BlockSyntaxOfEachControl) {
  // FANUC: % lines, O number, (comments), ";" ends the block, lengths with a point.
  const Program f = read("%\nO1000 (TEST)\nN10 G0 X1.5 Y2. ; end of block X9\nM30\n%\n", Dialect::fanuc);
  ASSERT_EQ(f.blocks.size(), 1u);
  EXPECT_DOUBLE_EQ(linear(f, 0).to_mm.y(), 2.0);
  EXPECT_NE(error_of("G0 X10", Dialect::fanuc).find("write X10. with the point"), std::string::npos);
  // SINUMERIK: archive header, ";" comments, "(" is no comment.
  const Program s = read("%_N_EICAL_MPF\n;$PATH=/_N_MPF_DIR\nN10 G0 X1 ; go\n", Dialect::sinumerik);
  ASSERT_EQ(s.blocks.size(), 1u);
  EXPECT_NE(error_of("G0 X1 (go)", Dialect::sinumerik).find("'(' opens no comment in SINUMERIK"), std::string::npos);
  // HEIDENHAIN ISO: begin/end blocks, "*" block end, ";" comments.
  const Program h =
      read("%EICAL G71 *\nN10 G00 X+1 Y-2 * ; a comment\nN99999999 %EICAL G71 *\n", Dialect::heidenhain_iso);
  ASSERT_EQ(h.blocks.size(), 1u);
  EXPECT_DOUBLE_EQ(linear(h, 0).to_mm.y(), -2.0);
  EXPECT_NE(error_of("N10 G00 X+1 * Y2", Dialect::heidenhain_iso).find("text after the block end"), std::string::npos);
  // Another control's syntax, read as LinuxCNC (the default), names that control.
  EXPECT_EQ(error_of("N10 G00 X+1 *", Dialect::linuxcnc),
            "user.nc:1:13: '*' ends a block in HEIDENHAIN ISO programs; this file is read as LinuxCNC (choose the "
            "control with --dialect)");
  EXPECT_NE(error_of("%EICAL G71 *", Dialect::linuxcnc).find("'%<NAME> G71 *' a HEIDENHAIN ISO one"),
            std::string::npos);
  EXPECT_NE(error_of("%_N_EICAL_MPF", Dialect::fanuc).find("'%_N_<NAME>_MPF' begins a SINUMERIK program"),
            std::string::npos);
  EXPECT_NE(error_of("%\nO1000 (T)", Dialect::linuxcnc).find("user.nc:2:1: O<n> is a FANUC program number"),
            std::string::npos);
}

TEST(GcodeDialectRead, HeidenhainCircleCentreIsAbsoluteAndModal) {
  const Program h =
      read("N10 G00 X+10 Y+0 *\nN20 I+0 J+0 *\nN30 G03 X+0 Y+10 F1000 *\nN40 G03 X-10 Y+0 *", Dialect::heidenhain_iso);
  ASSERT_EQ(h.blocks.size(), 3u);
  const Arc& a = std::get<Arc>(h.blocks[1]);
  EXPECT_NEAR(a.center_mm.norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.sweep_rad, 1.5707963267948966, 1e-12);
  EXPECT_NEAR(std::get<Arc>(h.blocks[2]).center_mm.norm(), 0.0, 1e-12) << "the centre stays for the next arc";
  EXPECT_FALSE(h.exact_stop) << "a TNC contours continuously";
  EXPECT_NE(error_of("N10 G00 X+10 *\nN20 G02 X-10 F100 *", Dialect::heidenhain_iso).find("without a circle centre"),
            std::string::npos);
}

TEST(GcodeDialectRead, NoMotionIsRefusedWithTheFileName) {
  for (const char* text : {"", "\n\n", "(only a comment)\n", "G4 P1\nM101\n"}) {
    try {
      (void)canonical_gcode(text, "/home/user/empty.ngc", Dialect::linuxcnc);
      ADD_FAILURE() << "accepted '" << text << "'";
    } catch (const dsp::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/home/user/empty.ngc: the program has no motion"), std::string::npos)
          << e.what();
    }
  }
}

TEST(GcodeDialectRead, CanonicalTextRunsLikeTheUsersProgram) {
  const std::string fanuc =
      "%\nO1 (T)\nG90 G21 G17 G64\nG0 X10. Y0.\nG04 P400\nM101\nG3 X0. Y10. I-10. J0. F1200\nG1 Z-1.\nM103\nM30\n%\n";
  const Program a = read(fanuc, Dialect::fanuc);
  const std::string text = canonical_gcode(fanuc, "user.nc", Dialect::fanuc);
  const Program b = parse(text, "canonical", {.start_mm = {10.0, 0.0, 0.0}});
  ASSERT_EQ(a.blocks.size(), b.blocks.size()) << text;
  EXPECT_EQ(a.exact_stop, b.exact_stop);
  EXPECT_DOUBLE_EQ(std::get<Dwell>(b.blocks[1]).duration_s, 0.4) << text;
  const Arc& arc = std::get<Arc>(b.blocks[3]);
  EXPECT_NEAR((arc.to_mm - Eigen::Vector3d(0, 10, 0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(arc.center_mm.norm(), 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(arc.feed_mm_min, 1200.0);
  EXPECT_EQ(std::get<Trigger>(b.blocks[5]).code, 103);
}

// An arc whose end lies just inside the radius tolerance stays readable once written: the
// canonical text rounds every coordinate to its resolution, and the reader allows for that
// (a fuzz finding: 7.070600 vs 7.071600 mm, read once, refused after writing).
TEST(GcodeDialectRead, AnArcAtTheRadiusToleranceStaysReadableOnceWritten) {
  int near_the_edge = 0;
  for (int k = 0; k < 2000; ++k) {
    // Start radius r, end radius r + 1e-3 - eps with eps across the rounding quantum.
    const double r = 1.0 + 0.0137 * k, eps = (k % 40 - 20) * 1e-10;
    char text[256];
    std::snprintf(
        text, sizeof text,
        "N10 G00 X+%.10f Y+0.3333333333 *\nN20 I+0 J+0.3333333333 *\nN30 G02 X-%.10f Y+0.3333333333 F1000 *\n", r,
        r + 1e-3 - eps);
    Program original;
    try {
      original = read(text, Dialect::heidenhain_iso);
    } catch (const dsp::InputError&) {
      continue;  // outside the tolerance as written: not this test's case
    }
    ++near_the_edge;
    const std::string kept = canonical_gcode(text, "user.nc", Dialect::heidenhain_iso);
    EXPECT_NO_THROW((void)parse(kept, "canonical")) << text << "\n" << kept;
  }
  EXPECT_GT(near_the_edge, 500) << "the sweep must cross the edge of the tolerance";
}

}  // namespace eical::sim::gcode
