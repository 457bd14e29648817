#pragma once
// LinuxCNC 2.9 compensation: COMP_FILE tables, BACKLASH, and the [JOINT_n] sections that
// carry them, written as a snippet or merged into the machine's INI file.
//
// What LinuxCNC does with them (docs/src/config/ini-config.adoc, [JOINT_<num>] BACKLASH,
// COMP_FILE, COMP_FILE_TYPE; src/emc/motion/usrmotintf.cc usrmotLoadComp;
// src/emc/motion/control.c compute_screw_comp and output_to_hal, LinuxCNC/linuxcnc):
// * COMP_FILE_TYPE = 0: each line "nominal forward reverse", forward/reverse = the ACTUAL
//   position the joint reaches when commanded `nominal` moving in + / −. usrmotLoadComp
//   stores trim = nominal − actual; compute_screw_comp interpolates the trim of the
//   direction the joint moves in (vel_cmd > 0 forward, < 0 reverse, at rest the last one
//   stays) and output_to_hal sets motor-pos-cmd = pos-cmd + trim (ramped, backlash_filt).
//   In eical's convention actual = nominal + deviation, so trim = −deviation = correction.
// * Nominal values must increase; at most 256 triplets per joint (EMCMOT_COMP_SIZE); beyond
//   the first/last nominal the end trim is held.
// * BACKLASH = b: without a COMP_FILE the trim is +b/2 moving in +, −b/2 moving in −.
//   "If COMP_FILE is specified for a joint, BACKLASH is not used": with a table the lost
//   motion is folded into its forward/reverse columns instead.
// * The compensation acts on joint.N.motor-pos-cmd; joint.N.pos-cmd stays the programmed
//   joint position (which is why the kit samples pos-cmd as the set-point).
#include "dsp/comp/axis_table.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace eical::tools::comp {

inline constexpr std::size_t kLinuxcncMaxCompPoints = 256;

// The COMP_FILE_TYPE 0 text of a table (mm, nominal ascending); InputError beyond 256 lines.
std::string linuxcnc_comp_file(const dsp::comp::AxisTable& t, const std::string& comment);

struct JointSettings {
  int joint = 0;
  char axis = 'x';
  std::optional<double> backlash_mm;     // BACKLASH (only without a COMP_FILE)
  std::optional<std::string> comp_file;  // COMP_FILE (type 0), relative to the INI's folder
  std::vector<std::string> comments;     // written above the keys
};

// Which joint moves which axis letter in a machine INI: trivkins only (its coordinates=
// parameter, else [TRAJ]COORDINATES, else X Y Z); InputError naming the file otherwise.
std::map<char, int> joint_map(const std::string& ini_text, const std::string& ini_name);

// One [JOINT_n] section per joint, ascending; InputError if a joint appears twice or has
// both BACKLASH and COMP_FILE.
std::string linuxcnc_ini_snippet(const std::vector<JointSettings>& joints, const std::string& header);

// The machine INI with the joints' BACKLASH / COMP_FILE / COMP_FILE_TYPE set: replaced
// lines are kept as comments, a BACKLASH next to a new COMP_FILE is set to 0 (LinuxCNC
// would ignore it anyway; 0 says so), missing keys go to the end of their section, a
// missing section to the end of the file. Everything else is copied byte for byte.
std::string merge_linuxcnc_ini(const std::string& ini_text, const std::string& ini_name,
                               const std::vector<JointSettings>& joints);

}  // namespace eical::tools::comp
