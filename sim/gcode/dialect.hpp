#pragma once
// The calibration programs for the control that runs them. eical's generators write one
// canonical ISO text (LinuxCNC's RS-274, what the simulator reads); a dialect writer turns
// it into a complete program for one control: its program start and number, its dwell
// word and unit, its comment syntax, its arc-centre form and its program end. Units: FANUC
// lengths always carry a decimal point; SINUMERIK G21 → G71, G20 → G700 (lengths and feed,
// as LinuxCNC's G20); HEIDENHAIN ISO is mm only (G20 is refused). eical's reader
// (parser.hpp) reads every one of them back; tests/sim/gcode_dialect_property_test.cpp and
// tests/tools/gcode_dialect_round_trip_test.cpp hold it to the same path and dwells.
//
// | dialect         | start / number               | dwell (canonical G4 P<s>) | end               |
// |-----------------|------------------------------|---------------------------|-------------------|
// | linuxcnc        | (title) comment              | G4 P<s>  seconds [1]      | M2 [1]            |
// | fanuc           | % , O<number> (TITLE)        | G04 P<ms> milliseconds [2]| M30 , %  [2]      |
// | sinumerik       | %_N_<NAME>_MPF, ;$PATH=... [3]| G4 F<s> seconds [3]      | M30 [3]           |
// | heidenhain-iso  | %<NAME> G71 * [4]            | G04 F<s> seconds [4]      | N99999999 %<NAME> G71 * [4] |
//
// [1] LinuxCNC G-code reference: "G4 P- ... dwell in seconds"; a program ends with M2/M30
//     (or %). The dwell in seconds is also what eical's reader takes.
// [2] FANUC dwell: P in milliseconds without decimal point, X in seconds; a program is
//     "O<number>" between "%" lines, ended by M30 (FANUC operator's manuals; not checked
//     against a manual here). Comments in parentheses, upper case.
// [3] SINUMERIK: G4 F<s> dwell in seconds, G71 metric, G60 exact stop, G64 continuous
//     path, ";" comments, M30 end, the "%_N_..._MPF" / ";$PATH=/_N_MPF_DIR" header of a
//     main program in the archive format (SINUMERIK programming manual Fundamentals; not
//     checked against a manual here). Arc centres I/J/K incremental as in ISO.
// [4] HEIDENHAIN TNC DIN/ISO: every block "N<n> ... *", program begin "%<name> G71 *" and
//     end "N99999999 %<name> G71 *", dwell G04 F<s>; circle centre I/J/K in a block of its
//     own before G02/G03, absolute under G90 (TNC 426/425 user's manual, "Circle in
//     Cartesian coordinates": "G02 around a circle center I, J"). Not checked against a
//     manual here: G04 F and the begin/end line; comments are left out (their block form
//     was not found) and there is no modal exact stop (G61/G64 are dropped: every target
//     of the calibration programs ends in a dwell anyway).
// The measurement M-functions M101–M103 stay as they are: on FANUC, SINUMERIK and
// HEIDENHAIN controls the PLC decodes them (docs/service.md, "How M101/M102/M103 reach eicald").
// eical's reader takes the same dialects back (parser.hpp: the reading rules and where
// each unit comes from).
#include "sim/gcode/dialect_id.hpp"

#include <string>

namespace eical::sim::gcode {

struct ProgramIdentity {
  int number = 1000;           // FANUC O-number
  std::string name = "EICAL";  // SINUMERIK / HEIDENHAIN program name (letters, digits, _)
  std::string title;           // one line saying what the program is
};

// The canonical program as a complete program for the dialect. InputError naming the
// line when the canonical text holds something the dialect writer does not know.
std::string write_dialect(const std::string& canonical, Dialect d, const ProgramIdentity& id);

}  // namespace eical::sim::gcode
