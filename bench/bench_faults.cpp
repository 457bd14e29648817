// The fault table of issue 21: every case of the fault harness (tests/faults/harness)
// injected into the real service, with what it did: outcome, recovery time, completed runs
// intact, data lost. Then the fuzzing totals of a scripts/fuzz-long work directory
// (executions, coverage, findings per target), when one is given.
//   bench_faults [--cases disk_full,...] [--fuzz /tmp/eical-fuzz-long]
#include "tests/faults/harness/fault_cases.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace {

namespace fs = std::filesystem;
using eical::faults::FaultOutcome;

const char* yes(bool b) { return b ? "yes" : "NO"; }

void print_row(const std::string& name, const FaultOutcome& o) {
  char recovery[32] = "-";
  if (std::isfinite(o.recovery_s)) std::snprintf(recovery, sizeof recovery, "%.3f s", o.recovery_s);
  std::printf("%-28s %-5s %-7s %-5s %3zu/%-3zu %3zu %9s  %s\n", name.c_str(), yes(o.service_alive),
              o.flagged ? "yes" : "-", o.clean ? "yes" : "-", o.runs_intact, o.runs_before, o.runs_after, recovery,
              o.data_lost.c_str());
  std::printf("%-28s   %s: %s\n", "", o.fault.c_str(), o.outcome.c_str());
  for (const auto& p : o.problems) std::printf("%-28s   PROBLEM: %s\n", "", p.c_str());
  std::fflush(stdout);
}

// The last status line of a libFuzzer log ("#N: cov: C ft: F ... oom/timeout/crash: a/b/c
// time: Ts" in fork mode, "#N DONE cov: C ft: F" otherwise) and the findings kept.
void print_fuzz(const fs::path& dir) {
  std::vector<fs::path> targets;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory() && fs::exists(e.path() / "log")) targets.push_back(e.path());
  std::sort(targets.begin(), targets.end());
  std::printf(
      "\nfuzzing (scripts/fuzz-long, %s): target, minutes, executions, cov, ft, oom/timeout/crash, findings kept\n",
      dir.c_str());
  const std::regex line(R"(^#(\d+):?\s.*cov: (\d+) ft: (\d+).*)");
  const std::regex fork(R"(oom/timeout/crash: (\d+/\d+/\d+) time: (\d+)s)");
  unsigned long long total = 0;
  for (const auto& t : targets) {
    std::ifstream is(t / "log");
    std::string l, last, execs = "?", cov = "?", ft = "?", oom = "-", secs = "?";
    while (std::getline(is, l))
      if (std::regex_match(l, line)) last = l;
    std::smatch m;
    if (std::regex_match(last, m, line)) execs = m[1], cov = m[2], ft = m[3];
    if (std::regex_search(last, m, fork)) oom = m[1], secs = m[2];
    std::size_t kept = 0;
    if (fs::exists(t / "artifacts"))
      for ([[maybe_unused]] const auto& a : fs::directory_iterator(t / "artifacts")) ++kept;
    if (execs != "?") total += std::stoull(execs);
    const double minutes = secs == "?" ? std::nan("") : std::stod(secs) / 60.0;
    std::printf("  %-20s %5.1f  %12s  %5s  %6s  %-7s  %zu\n", t.filename().c_str(), minutes, execs.c_str(), cov.c_str(),
                ft.c_str(), oom.c_str(), kept);
  }
  std::printf("  all targets: %llu executions\n", total);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("eical fault table: faults injected into eicald, what each did");
  std::vector<std::string> only;
  std::string fuzz_dir;
  app.add_option("--cases", only, "cases to run (default: all)")->delimiter(',');
  app.add_option("--fuzz", fuzz_dir, "a scripts/fuzz-long work directory: print its totals");
  CLI11_PARSE(app, argc, argv);
  std::printf("%-28s %-5s %-7s %-5s %-7s %3s %9s  %s\n", "fault", "alive", "flagged", "clean", "intact", "new",
              "recovery", "data lost");
  int failed = 0;
  for (const auto& c : eical::faults::all_cases()) {
    if (!only.empty() && std::find(only.begin(), only.end(), c.name) == only.end()) continue;
    const FaultOutcome o = c.run();
    failed += o.problems.empty() ? 0 : 1;
    print_row(c.name, o);
  }
  std::printf(
      "alive: measuring again afterwards; flagged: a degraded result or Status.fault names the cause; clean: no "
      "temporary or torn\n"
      "run left; intact: completed runs before the fault unchanged byte for byte / runs before; new: runs written "
      "during and after.\n");
  if (!fuzz_dir.empty()) print_fuzz(fuzz_dir);
  return failed == 0 ? 0 : 1;
}
