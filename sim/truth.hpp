#pragma once
// truth.toml of a synthetic run: what was put into the data, in the layout of the sample
// runs' truth files (docs/run-format.md, tests/data/*/truth.toml): the effects
// present and in the background with their parameters, the true sensors, machine errors,
// DAQ, site, NC timing, vibration, PSD and reference. Plain text formatting: sim/ does
// not depend on a TOML library.
#include "sim/nc/set_point.hpp"
#include "sim/scenario.hpp"

#include <string>

namespace eical::sim {

std::string truth_toml(const Scenario& scenario, const nc::SetPoint& set_point);

}  // namespace eical::sim
