#include "sim/gcode/dialect_id.hpp"

#include "dsp/core/error.hpp"

namespace eical::sim::gcode {

Dialect dialect_from_name(const std::string& name) {
  if (name == "linuxcnc") return Dialect::linuxcnc;
  if (name == "fanuc") return Dialect::fanuc;
  if (name == "sinumerik") return Dialect::sinumerik;
  if (name == "heidenhain-iso") return Dialect::heidenhain_iso;
  throw dsp::InputError("dialect '" + name + "' is not linuxcnc, fanuc, sinumerik or heidenhain-iso");
}

const char* dialect_name(Dialect d) noexcept {
  switch (d) {
    case Dialect::linuxcnc: return "linuxcnc";
    case Dialect::fanuc: return "fanuc";
    case Dialect::sinumerik: return "sinumerik";
    case Dialect::heidenhain_iso: return "heidenhain-iso";
  }
  return "?";
}

const char* dialect_title(Dialect d) noexcept {
  switch (d) {
    case Dialect::linuxcnc: return "LinuxCNC";
    case Dialect::fanuc: return "FANUC";
    case Dialect::sinumerik: return "SINUMERIK";
    case Dialect::heidenhain_iso: return "HEIDENHAIN ISO";
  }
  return "?";
}

}  // namespace eical::sim::gcode
