#pragma once
// What a G-code number means on each control eical reads (the modal and motion codes of
// calibration and part programs), and, for a code this control does not take, which
// other controls do: the reader's hint that a file was read in the wrong dialect.
#include "sim/gcode/dialect_id.hpp"

#include <string>

namespace eical::sim::gcode {

enum class GAction {
  motion,                  // G0..G3 (`motion` below)
  dwell,                   // G4: the dwell word and its unit are the dialect's (parser.cpp)
  plane_xy,                // G17
  plane_zx,                // G18
  plane_yz,                // G19
  inch_positions,          // SINUMERIK G70: lengths in inch, the feed stays in the base system
  metric_positions,        // SINUMERIK G71
  inch,                    // LinuxCNC/FANUC G20, SINUMERIK G700, HEIDENHAIN G70: lengths and feed
  metric,                  // G21, G710, HEIDENHAIN G71
  exact_stop,              // G61 (SINUMERIK G60), modal
  continuous_path,         // G64
  absolute,                // G90
  incremental,             // G91
  arc_centre_absolute,     // LinuxCNC G90.1
  arc_centre_incremental,  // LinuxCNC G91.1
  feed_per_minute,         // G94, the only feed mode eical runs
  cancel,                  // G40/G49/G80 of a safety line: the state eical simulates anyway
  first_work_offset,       // G54: the program's coordinates are the set-point
  unsupported,
};

struct GMeaning {
  GAction action = GAction::unsupported;
  int motion = -1;  // 0..3 for GAction::motion
};

GMeaning g_meaning(double code, Dialect d);

// For a code `d` does not take: ": SINUMERIK and HEIDENHAIN ISO mean metric by it; this
// file is read as LinuxCNC (--dialect)"; empty when no other control takes it either.
std::string other_dialects_hint(double code, Dialect d);

}  // namespace eical::sim::gcode
