#pragma once
// Which control a G-code program is written for: one enum for eical's dialect writer
// (dialect.hpp) and its reader (parser.hpp), and the names the command line uses for it
// (gen-nc --dialect, simulate --dialect).
#include <string>

namespace eical::sim::gcode {

enum class Dialect { linuxcnc, fanuc, sinumerik, heidenhain_iso };

// "linuxcnc", "fanuc", "sinumerik", "heidenhain-iso"; InputError otherwise.
Dialect dialect_from_name(const std::string& name);
const char* dialect_name(Dialect d) noexcept;
// The control's name for messages: "LinuxCNC", "FANUC", "SINUMERIK", "HEIDENHAIN ISO".
const char* dialect_title(Dialect d) noexcept;

}  // namespace eical::sim::gcode
