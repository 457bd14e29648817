// Fuzz target: fanuc G-code through sim::gcode::parse with that dialect's rules, and the
// canonical text simulate keeps of it (fuzz/gcode_check.hpp).
#include "fuzz/gcode_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  eical::fuzz::read_dialect(eical::fuzz::as_text(data, size), eical::sim::gcode::Dialect::fanuc);
  return 0;
}
