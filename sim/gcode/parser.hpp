#pragma once
// G-code reader for calibration programs and real part programs run as free-form tests,
// in the dialect of the control the program is written for (the one enum gen-nc writes):
// G0/G1/G2/G3 (I/J/K or R), G4 dwell, G17/G18/G19, inch/metric, exact stop/continuous
// path, G90/G91, G94; the safety-line cancels G40/G49/G80 and G54; F, N, S and T (no
// effect on the path), M-functions (spindle, coolant, tool change and program end pass,
// M100–M199 are triggers); the lexical rules of words.hpp (comments, "%" lines, "*").
//
// | dialect        | dwell                              | inch / metric          | arc centre I/J/K       |
// |----------------|------------------------------------|------------------------|------------------------|
// | linuxcnc       | G4 P<s> [1]                        | G20 / G21              | from the start; G90.1  |
// | fanuc          | G04 P<ms> integer; G04 X<s> [2]    | G20 / G21              | from the start         |
// | sinumerik      | G4 F<s>; G4 S<revolutions> [3]     | G70/G71, G700/G710 [4] | from the start         |
// | heidenhain-iso | G04 F<s> [5]                       | G70 / G71 [6]          | circle centre CC [7]   |
//
// [1] LinuxCNC / EMC handbook, "Dwell - G4": "G4 P... the period of time in seconds specified
//     by the P number" (emc.sourceforge.net/Handbook/node57.html).
// [2] FANUC: P in milliseconds without a decimal point (G04 P1200 = 1.2 s), X in seconds with
//     one; a number without a decimal point is counted in least input increments unless
//     parameter 3401#0 (DPI) says otherwise, so FANUC axis, centre, radius and G04 X words
//     without a "." are refused as ambiguous (gcodepractice.com "G04 Dwell Time Format:
//     Fanuc vs Haas", a FANUC operator's course page at zanotowane.pl; no FANUC manual found).
// [3] SINUMERIK: "G4 F... dwell time in s", "G4 S... in revolutions of the master spindle";
//     F and S programmed before the G4 block stay in force (SINUMERIK programming text on
//     cloud.tencent.com/developer/article/1100156, "暂停时间指令 (G4)"; no Siemens manual
//     found). G4 S needs the spindle turning: M3/M4 with S<rpm> before.
// [4] SINUMERIK 802D sl / 808D programming manuals, "Dimensions in metric units and inches:
//     G71, G70, G710, G700": G70/G71 scale the lengths only, G700/G710 also F. The control's
//     base system is taken as metric.
// [5] HEIDENHAIN ISO G04 F<s>: not found in a HEIDENHAIN manual here (the TNC 640 ISO manual
//     gives the dwell of cycle 9 in s); it is what eical's writer emits (dialect.hpp).
// [6] In the begin and end blocks "%NAME G71 *"; G70 inch also for the feed.
// [7] I/J/K set the circle centre CC, modal, absolute under G90 (from the position under
//     G91), in a block of their own or the arc's (TNC 426/425 user's manual, "Circle in
//     Cartesian coordinates"). The TNC contours continuously (no modal exact stop): a
//     HEIDENHAIN program reads as G64.
// Anything else — another motion word (G5, G33, G38, canned cycles G73–G89, G28), tool
// length offsets, O-word subroutines, parameters — is an InputError naming file, line and
// column: a calibration must never run a program it only half understood. A code or word
// that only another control takes says so ("... this file is read as LinuxCNC").
#include "sim/gcode/dialect_id.hpp"
#include "sim/gcode/program.hpp"

#include <string_view>

namespace eical::sim::gcode {

// The resolution eical writes a coordinate at (linuxcnc_text: 9 decimals of a mm). A check
// that compares lengths allows a few of these, so that a program read once is read again
// after writing: rounding the start, end and centre moves the two radii by ≤ 3 nm.
inline constexpr double kWrittenResolutionMm = 1e-9;

struct ParseOptions {
  Eigen::Vector3d start_mm = Eigen::Vector3d::Zero();  // machine position before the program
  // M-codes passed through as triggers; other M-codes are accepted only if listed in
  // `ignored_m` (spindle, coolant, program end) — everything else is an error.
  std::vector<int> ignored_m = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30};
  double arc_radius_tolerance_mm = 1e-3;  // |start radius − end radius| allowed (I/J/K form)
  Dialect dialect = Dialect::linuxcnc;
};

// `name` is used in error messages ("circle.ngc:12:5: ...").
Program parse(std::string_view text, std::string_view name = "gcode", const ParseOptions& options = {});

// InputError "<name>: no motion ..." when the program has no G0/G1/G2/G3 move (an empty
// file, a file of comments, or dwells only): nothing to calibrate with.
void require_motion(const Program& program, std::string_view name);

}  // namespace eical::sim::gcode
