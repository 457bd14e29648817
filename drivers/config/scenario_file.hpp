#pragma once
// Simulation scenario files (`eical simulate --scenario FILE`, format "eical-scenario/1"):
// the run.toml sections for what eical is told (nominal data sheet, program, site, PSD,
// reference), plus the truth — every effect of docs/run-format.md switched on by an
// `[effects."<name>"]` table with its parameters. Strict: unknown keys, unknown effects
// and out-of-range values are errors naming the file, line and key.
// config/scenarios/README.md documents every key; config/scenarios/*.toml are examples.
#include "sim/gcode/dialect_id.hpp"
#include "sim/scenario.hpp"

#include <string>

namespace eical::drivers {

// `gcode_dialect`: the control a [program] gcode_file is written for (simulate --dialect).
sim::Scenario read_scenario_file(const std::string& path,
                                 sim::gcode::Dialect gcode_dialect = sim::gcode::Dialect::linuxcnc);

}  // namespace eical::drivers
