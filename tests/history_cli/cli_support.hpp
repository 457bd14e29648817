#pragma once
// The history command line under test: run directories with a run.toml and a result.json
// that carries uncertainty_k2 and quality.verdict (issue 16's form), and running the real
// `eical` binary.
#include "drivers/run_io/run_writer.hpp"
#include "sim/scenario.hpp"
#include "tests/hil/child_process.hpp"
#include "tests/history/history_support.hpp"

#include <fstream>
#include <vector>

namespace eical::test {

// A run directory as eicald leaves it (run.toml + result.json; no samples are needed to
// add a run that has its result).
inline fs::path write_run_dir(const fs::path& parent, const std::string& machine, const std::string& run_id,
                              const std::string& created, const CircleFigures& f) {
  const fs::path dir = parent / run_id;
  fs::create_directories(dir);
  dsp::RunMeta meta = sim::circle_scenario(10.0, 2500.0, 2).meta;
  meta.id = run_id;
  meta.created = created;
  meta.machine.name = machine;
  std::ofstream(dir / "run.toml") << drivers::run_toml_text(meta);
  std::ofstream(dir / "result.json") << circle_result(run_id, f).dump(2);
  return dir;
}

inline std::string slurp(const fs::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

struct CliResult {
  int code = -1;
  std::string out;
};

// Runs `eical ARGS...`; stdout captured (stderr too when `with_stderr`).
inline CliResult eical_cli(std::vector<std::string> args, bool with_stderr = false) {
  args.insert(args.begin(), EICAL_CLI);
  if (with_stderr) {
    // run_capture keeps stderr apart: a shell joins them.
    std::string cmd;
    for (const auto& a : args) cmd += "'" + a + "' ";
    args = {"/bin/sh", "-c", cmd + "2>&1"};
  }
  CliResult r;
  r.out = run_capture(args, std::chrono::seconds(120), &r.code).value_or("");
  return r;
}

}  // namespace eical::test
