// eical validate-sim: the simulator against the thesis' figures (issue 3's proof table).
#include "tools/commands.hpp"
#include "tools/validate/thesis_checks.hpp"

#include <cstdio>
#include <memory>

namespace eical::tools {

void register_validate_sim(CLI::App& app) {
  auto o = std::make_shared<ValidationOptions>();
  auto* cmd =
      app.add_subcommand("validate-sim", "Compare the simulator with the thesis' measured and simulated figures");
  cmd->add_option("--windows", o->monte_carlo_windows, "Monte-Carlo windows for the noise checks")
      ->default_val(400)
      ->check(CLI::Range(20, 100000));
  cmd->add_option("--seed", o->seed, "random seed")->default_val(1);
  cmd->callback([o] {
    const auto rows = validate_against_thesis(*o);
    std::printf("%-58s %-34s %10s %10s %6s %-13s %s\n", "check", "thesis source", "thesis", "simulated", "ratio",
                "accepted", "");
    int failed = 0;
    for (const auto& r : rows) {
      std::printf("%-58s %-34s %8.3g %s %8.3g %s %6.3f %5.2f..%-5.2f %s\n", r.name.c_str(), r.source.c_str(), r.thesis,
                  r.unit.c_str(), r.simulated, r.unit.c_str(), r.ratio(), r.ratio_min, r.ratio_max,
                  r.within() ? "ok" : "OUT");
      failed += r.within() ? 0 : 1;
    }
    std::printf("\nhow each simulated figure was obtained:\n");
    for (const auto& r : rows) std::printf("  %s: %s\n", r.name.c_str(), r.how.c_str());
    if (failed) throw CLI::RuntimeError(1);
  });
}

}  // namespace eical::tools
