#pragma once
// ISO G-code (RS-274 subset) reader for calibration programs and real part programs run as
// free-form tests: G0/G1/G2/G3 (I/J/K or R), G4 dwell (P in seconds, LinuxCNC), G17/G18/
// G19, G20/G21, G61/G64, G90/G91, G90.1/G91.1, G94; the safety-line cancels G40/G49/G80
// and G54; F, N, O (program number), S and T (no effect on the path), M-functions (spindle,
// coolant, tool change and program end pass, M100–M199 are triggers); "%" lines, block
// delete "/", comments in parentheses or after ';'. Anything else — another motion word
// (G5, G33, G38, canned cycles G73–G89, G28), tool length offsets, O-word subroutines,
// parameters — is an InputError naming line and column: a calibration must never run a
// program it only half understood.
#include "sim/gcode/program.hpp"

#include <string_view>

namespace eical::sim::gcode {

struct ParseOptions {
  Eigen::Vector3d start_mm = Eigen::Vector3d::Zero();  // machine position before the program
  // M-codes passed through as triggers; other M-codes are accepted only if listed in
  // `ignored_m` (spindle, coolant, program end) — everything else is an error.
  std::vector<int> ignored_m = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30};
  double arc_radius_tolerance_mm = 1e-3;  // |start radius − end radius| allowed (I/J/K form)
};

// `name` is used in error messages ("circle.ngc:12:5: ...").
Program parse(std::string_view text, std::string_view name = "gcode", const ParseOptions& options = {});

}  // namespace eical::sim::gcode
