#pragma once
// A user's G-code in its control's dialect, as eical keeps and simulates it: read with the
// dialect's rules (errors name the user's file and line), refused without motion, and made
// canonical — LinuxCNC text, the form run.toml's [program] gcode, gen-nc --meta and the
// simulator take. A LinuxCNC program stays as written (its comments and line numbers); a
// program of another control is written from what was read: absolute mm, G4 P<seconds>.
#include "sim/gcode/dialect_id.hpp"
#include "sim/gcode/program.hpp"

#include <string>
#include <string_view>

namespace eical::sim::gcode {

std::string canonical_gcode(std::string_view text, std::string_view name, Dialect d);

// The program as LinuxCNC text: every move with X, Y and Z absolute (9 decimals), arc
// centres incremental (G91.1), feeds in mm/min, dwells in seconds, triggers with P and Q.
std::string linuxcnc_text(const Program& program);

}  // namespace eical::sim::gcode
