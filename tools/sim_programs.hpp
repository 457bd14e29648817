#pragma once
// The free-form contour `eical simulate --program freeform` runs (the simulator's own
// built-in scenarios cover circle, step, positioning and rectangle).
#include "sim/scenario.hpp"

#include <cstdint>
#include <string>

namespace eical::tools {

// A free-form contour in XY (lines and arcs blended with G64, then back to the start).
sim::Scenario freeform_scenario(double feed_mm_min, std::uint64_t seed);

// The G-code of freeform_scenario().
std::string freeform_gcode(double feed_mm_min);

}  // namespace eical::tools
