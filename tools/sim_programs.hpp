#pragma once
// Scenarios for the program kinds the simulator has no built-in scenario for (rectangle,
// free form, partial arcs): the circle scenario's machine and sensors with another
// [program]; the simulator runs the G-code the generator writes for it.
#include "sim/scenario.hpp"

#include <cstdint>
#include <string>

namespace eical::tools {

// Rectangle `size_a_mm` × `size_b_mm` from the origin in `plane`, exact stop at the corners.
sim::Scenario rectangle_scenario(double size_a_mm, double size_b_mm, double feed_mm_min, const std::string& plane, std::uint64_t seed);

// A free-form contour in XY (lines and arcs blended with G64, then back to the start).
sim::Scenario freeform_scenario(double feed_mm_min, std::uint64_t seed);

// The G-code of freeform_scenario().
std::string freeform_gcode(double feed_mm_min);

}  // namespace eical::tools
