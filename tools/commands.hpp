#pragma once
// Every `eical` subcommand is one file tools/cmd_<name>.cpp exposing one register function.
// A command reports failure by throwing (message printed as "eical: <what>", exit 1) or
// CLI::RuntimeError(code) for a specific exit code (tools/exit_codes.hpp).
#include <CLI/CLI.hpp>

namespace eical::tools {

void register_version(CLI::App& app);
void register_gen_nc(CLI::App& app);
void register_simulate(CLI::App& app);
void register_analyze(CLI::App& app);
void register_report(CLI::App& app);
void register_demo(CLI::App& app);
void register_lincomp(CLI::App& app);
void register_fourier(CLI::App& app);
void register_volumetric(CLI::App& app);
void register_iso230_2(CLI::App& app);
void register_comp(CLI::App& app);
void register_hmi(CLI::App& app);
void register_validate_sim(CLI::App& app);
void register_identify(CLI::App& app);
void register_explain(CLI::App& app);
void register_plan(CLI::App& app);
void register_help(CLI::App& app);
void register_import(CLI::App& app);
void register_history(CLI::App& app);
void register_collect(CLI::App& app);

// The list main() registers, in the order `eical --help` shows them.
inline void register_all(CLI::App& app) {
  register_demo(app);
  register_simulate(app);
  register_import(app);
  register_validate_sim(app);
  register_analyze(app);
  register_plan(app);
  register_identify(app);
  register_explain(app);
  register_hmi(app);
  register_history(app);
  register_collect(app);
  register_report(app);
  register_iso230_2(app);
  register_gen_nc(app);
  register_comp(app);
  register_lincomp(app);
  register_fourier(app);
  register_volumetric(app);
  register_version(app);
  register_help(app);
}

}  // namespace eical::tools
