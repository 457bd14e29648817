#pragma once
// truth.toml of a synthetic run: what was put into the data (layout of the sample runs'
// truth files, shared/spec/run-format.md). Plain text formatting: sim/ does not depend on
// a TOML library.
#include "sim/nc/trajectory.hpp"
#include "sim/scenario.hpp"

#include <string>

namespace eical::sim {

std::string truth_toml(const Scenario& scenario, const nc::Trajectory& trajectory);

}  // namespace eical::sim
