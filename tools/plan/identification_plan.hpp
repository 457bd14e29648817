#pragma once
// The on-site identification a planned test needs (issue 33): swings across the test's
// own strips, inside the travel the test moves the axes over where it spans the swing (so
// that the identification runs where the test runs), centred on a shorter one; about a
// circle, as far beyond it as a strip on its end needs to be crossed whole. z, which no
// strip measures, is swung from where the head rests.
#include "sim/gcode/generate.hpp"
#include "tools/plan/predicted_uncertainty.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace eical::tools::plan {

// The travel of x and y the program moves over, in its coordinates (a circle about 0,0, a
// positioning or step test on x, a rectangle from the origin); unset for an axis it holds.
void test_travel(const TestProgram& p, std::optional<sim::gcode::AxisTravel> (&travel_mm)[2]);
// The identification plan: the test's strips (strips_for when it names none), z, the
// default swing shrunk to the travel (a circle's widened to reach its strips).
sim::gcode::IdentifyPlan identification_plan(const TestProgram& p);
// The gen-nc command that writes it, and the same as text and JSON for the plan's output.
std::string identification_command(const sim::gcode::IdentifyPlan& plan);
std::string identification_text(const sim::gcode::IdentifyPlan& plan);
nlohmann::json identification_json(const sim::gcode::IdentifyPlan& plan);

}  // namespace eical::tools::plan
