#pragma once
// One number formatted for a G-code word (printf format, e.g. "%.4f").
#include <cstdio>
#include <string>

namespace eical::sim::gcode {

inline std::string format_number(const char* printf_format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, printf_format, v);
  return buf;
}

}  // namespace eical::sim::gcode
