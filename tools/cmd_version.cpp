#include "tools/commands.hpp"

#include "drivers/results/software_version.hpp"

#include <cstdio>

namespace eical::tools {

void register_version(CLI::App& app) {
  auto* cmd = app.add_subcommand("version", "Print the eical version and the formats it speaks");
  cmd->callback([] {
    std::printf(
        "%s (eical-run/1, eical-result/1, eical-explain/1, eical-sensor-cal/1, eical-tolerances/1, eical-plan/1)\n",
        drivers::software_version());
  });
}

}  // namespace eical::tools
