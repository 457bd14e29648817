#include "tools/sim_programs.hpp"

#include "sim/simulate.hpp"

#include <cstdio>

namespace eical::tools {

std::string freeform_gcode(double feed_mm_min) {
  char f[32];
  std::snprintf(f, sizeof f, " F%.0f", feed_mm_min);
  return std::string("G90 G21 G17 G64 (free form: lines and arcs blended)\nG0 X0 Y0\nG4 P0.4\nM101\nG4 P0.1\n") +
         "G1 X10 Y0" + f + "\nG3 X15 Y5 I0 J5\nG1 X15 Y12\nG3 X9 Y18 I-6 J0\nG1 X2 Y14\nG1 X0 Y0\n" +
         "G4 P0.4\nM103\nG4 P0.1\n";
}

sim::Scenario freeform_scenario(double feed_mm_min, std::uint64_t seed) {
  sim::Scenario sc = sim::gcode_scenario(freeform_gcode(feed_mm_min), dsp::ProgramKind::freeform, seed);
  sc.meta.program.plane = "xy";
  sc.meta.program.feed_mm_min = feed_mm_min;
  sc.meta.id = "sim-freeform-s" + std::to_string(seed);
  sc.description = "free-form contour, ideal machine, data-sheet sensors";
  return sc;
}

}  // namespace eical::tools
