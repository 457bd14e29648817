#pragma once
// Builds the `linuxcnc` source from eicald's configuration: the scenario (machine and
// sensor truth, from [source.linuxcnc] scenario_file or an ideal machine) with what the
// daemon believes about its hardware ([acquisition], [sensors], ...) and the program
// LinuxCNC runs ([source.linuxcnc] program_file).
#include "daemon/config/daemon_config.hpp"
#include "drivers/source/source.hpp"

#include <memory>

namespace eical::daemon {

std::unique_ptr<drivers::Source> make_linuxcnc_source(const DaemonConfig& config);

}  // namespace eical::daemon
