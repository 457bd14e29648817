// Faults of the eicald process itself: kill -9 in the middle of the atomic write of a run.
// eicald runs as a child process (free-running simulator: a run written every couple of
// seconds, gzip), so the kill lands where a power cut or the OOM killer would.
#include "tests/faults/harness/eicald_process.hpp"
#include "tests/faults/harness/fault_cases.hpp"
#include "tests/faults/harness/recording_dir.hpp"

#include <csignal>
#include <thread>

namespace eical::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// A run being written: the writer's temporary directory (.<run>.tmp-N).
bool write_in_progress(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

std::size_t runs_with_result(const fs::path& dir) {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& r : completed_runs(dir)) n += fs::exists(r / "result.json", ec) ? 1 : 0;
  return n;
}

}  // namespace

FaultOutcome kill9_during_write() {
  FaultOutcome o;
  o.fault = "kill -9 during the atomic write of a run";
  Scratch s("kill9");
  const fs::path dir = s.dir / "runs";
  fs::create_directories(dir);
  const fs::path config = write_eicald_config(s.dir, dir);
  // Kill when a write is under way; the write may finish between the look and the kill,
  // so try until a temporary is left behind (a few attempts at most).
  bool torn = false;
  for (int attempt = 0; attempt < 8 && !torn; ++attempt) {
    EicaldProcess eicald(config, s.dir / "eicald-1.log");
    const auto end = Clock::now() + 60s;
    // After the first run: the second write is then one among earlier, completed runs.
    while (Clock::now() < end && eicald.running() && !(completed_runs(dir).size() >= 1 && write_in_progress(dir)))
      std::this_thread::sleep_for(200us);
    eicald.signal(SIGKILL);
    (void)eicald.wait_exit(5s);
    torn = write_in_progress(dir);
  }
  if (!torn) {
    o.problem("no kill landed inside a write in 8 attempts");
    return o;
  }
  // What the kill left: completed runs are whole (renamed into place), some without result.
  for (const auto& r : completed_runs(dir)) {
    std::error_code ec;
    if (fs::exists(r / "result.json", ec)) continue;
    ++o.runs_before;  // counted below with the others
  }
  const std::size_t unevaluated = o.runs_before;
  const Snapshot before = snapshot(dir);
  o.runs_before = runs_in(before);
  const std::size_t temps_left = temporaries(dir).size();

  // The next start (systemd's Restart=on-failure) cleans up and evaluates what was not.
  const auto t0 = Clock::now();
  EicaldProcess again(config, s.dir / "eicald-2.log");
  const auto end = Clock::now() + 60s;
  while (Clock::now() < end && again.running() && !(temporaries(dir).empty() && runs_with_result(dir) >= o.runs_before))
    std::this_thread::sleep_for(10ms);
  if (temporaries(dir).empty() && runs_with_result(dir) >= o.runs_before)
    o.recovery_s = std::chrono::duration<double>(Clock::now() - t0).count();
  else
    o.problem("after the restart: " + std::to_string(temporaries(dir).size()) + " temporaries, " +
              std::to_string(runs_with_result(dir)) + " of " + std::to_string(o.runs_before) + " runs with a result");
  // Measuring again: a run beyond those of the first start.
  while (Clock::now() < end + 30s && again.running() && completed_runs(dir).size() <= o.runs_before)
    std::this_thread::sleep_for(20ms);
  o.service_alive = completed_runs(dir).size() > o.runs_before;
  again.signal(SIGTERM);
  const auto rc = again.wait_exit(20s);
  if (rc != 0)
    o.problem("eicald did not stop cleanly after SIGTERM: " +
              (rc ? std::to_string(*rc) : std::string("still running")));
  o.runs_intact = intact_runs(before, dir);
  o.runs_after = completed_runs(dir).size() - o.runs_before;
  o.clean = temporaries(dir).empty();
  for (const auto& r : completed_runs(dir)) {
    std::string why;
    if (!readable_with_result(r, &why)) o.problem("after the restart: " + why);
  }
  const std::string log2 = again.log();
  o.flagged = unevaluated == 0 || log2.find("evaluated now") != std::string::npos;
  o.outcome = "no torn run directory; the next start removed " + std::to_string(temps_left) + " temporar" +
              (temps_left == 1 ? "y" : "ies") +
              (unevaluated ? " and evaluated " + std::to_string(unevaluated) +
                                 " run(s) left without result (flagged evaluated_after_restart)"
                           : "");
  o.measurements_lost = 1;
  o.data_lost = "the measurement being written (in the killed process's memory); no completed run";
  return o;
}

}  // namespace eical::faults
