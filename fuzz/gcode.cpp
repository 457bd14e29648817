// Fuzz target: LinuxCNC G-code (RS-274 subset, eical's default dialect) through
// sim::gcode::parse, and the canonical text simulate keeps of it (fuzz/gcode_check.hpp).
// The other controls' dialects have their own targets (gcode_fanuc, gcode_sinumerik,
// gcode_heidenhain_iso).
#include "fuzz/gcode_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  eical::fuzz::read_dialect(eical::fuzz::as_text(data, size), eical::sim::gcode::Dialect::linuxcnc);
  return 0;
}
