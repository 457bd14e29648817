// Faults of the recording's storage: the disk full, the directory removed, run ids taken
// after the wall clock stepped back. The service runs in this process (free-running
// simulator, the program repeated), so a measurement takes about a second.
#include "tests/faults/harness/fault_cases.hpp"
#include "tests/faults/harness/recording_dir.hpp"
#include "tests/faults/harness/service_thread.hpp"
#include "tests/support/file_size_limit.hpp"

#include <sys/resource.h>

#include <csignal>
#include <ctime>
#include <fstream>

namespace eical::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using eical::testing::FileSizeLimit;

// After the stop: every run readable with its result, nothing temporary left, and every
// measurement the service completed written (the last Status comes after the evaluator
// finished: its counts are final).
void account(FaultOutcome& o, const fs::path& dir, const daemon::ServiceStatus& last) {
  const auto runs = completed_runs(dir);
  for (const auto& r : runs) {
    std::string why;
    if (!readable_with_result(r, &why)) o.problem("not readable: " + why);
  }
  const auto temps = temporaries(dir);
  o.clean = temps.empty();
  if (!o.clean) o.problem("temporaries left: " + temps.front().string());
  o.measurements_lost = static_cast<std::int64_t>(last.measurements) - static_cast<std::int64_t>(last.results_written);
  o.data_lost = o.measurements_lost == 0 ? "0" : std::to_string(o.measurements_lost) + " measurements not recorded";
}

// When more than `known` runs are on disk (durable: renamed into place; the result follows
// after the analysis), polled every 10 ms.
bool wait_for_new_run(const fs::path& dir, std::size_t known, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    if (completed_runs(dir).size() > known) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

}  // namespace

FaultOutcome disk_full_mid_recording() {
  FaultOutcome o;
  o.fault = "disk full while recording (files capped at 64 KiB), then space freed";
  Scratch s("disk-full");
  const fs::path dir = s.dir / "runs";
  ServiceThread svc(base_config(dir));
  if (!svc.wait_for([](const auto& st) { return st.results_written >= 1; }, 60s)) {
    o.problem("no first result");
    return o;
  }
  const Snapshot before = snapshot(dir);
  o.runs_before = runs_in(before);
  daemon::ServiceStatus at_fault;
  Clock::time_point freed;
  {
    FileSizeLimit full(64 * 1024);
    // The measurement running now cannot be written: Status.fault says so, it is held.
    o.flagged = svc.wait_for([](const auto& st) { return st.fault.find("recording") != std::string::npos; }, 60s);
    at_fault = svc.last();
    std::this_thread::sleep_for(2s);  // the disk stays full over several retries
    full.lift();
    freed = Clock::now();
  }
  const std::uint64_t results_at_fault = at_fault.results_written;
  if (wait_for_new_run(dir, o.runs_before, 30s))
    o.recovery_s = seconds_since(freed);
  else
    o.problem("the held measurement was not written after space was freed");
  if (!svc.wait_for([&](const auto& st) { return st.fault.empty(); }, 10s))
    o.problem("Status.fault not cleared: " + svc.last().fault);
  o.service_alive = svc.wait_for([&](const auto& st) { return st.results_written > results_at_fault + 1; }, 60s);
  // The system's reason, as Status.fault gives it after the path ("...: File too large; retried ...").
  const std::string& f = at_fault.fault;
  const auto retried = f.find("; retried");
  const auto reason = f.rfind(": ", retried);
  o.outcome = "Status.fault \"recording ...: " + (reason == std::string::npos ? f : f.substr(reason + 2)) +
              "\"; written when space returned; " +
              std::to_string(svc.last().counters.triggers_refused - at_fault.counters.triggers_refused) +
              " M-codes refused (with a Reply) meanwhile";
  svc.stop();
  if (svc.error()) o.problem("the service ended with: " + *svc.error());
  o.runs_intact = intact_runs(before, dir);
  o.runs_after = completed_runs(dir).size() - o.runs_before;
  account(o, dir, svc.last());
  return o;
}

FaultOutcome recording_dir_removed() {
  FaultOutcome o;
  o.fault = "recording directory removed while running";
  Scratch s("dir-removed");
  const fs::path dir = s.dir / "runs";
  ServiceThread svc(base_config(dir));
  if (!svc.wait_for([](const auto& st) { return st.results_written >= 1; }, 60s)) {
    o.problem("no first result");
    return o;
  }
  const std::uint64_t results = svc.last().results_written;
  std::error_code ec;
  fs::remove_all(dir, ec);
  const auto t0 = Clock::now();
  if (wait_for_new_run(dir, 0, 60s)) o.recovery_s = seconds_since(t0);
  o.service_alive = svc.wait_for([&](const auto& st) { return st.results_written > results + 1; }, 60s);
  const daemon::ServiceStatus st = svc.last();
  o.flagged = false;  // nothing to flag: the next run goes into the directory made again
  o.outcome = "the directory is made again; the next measurement is written into it" +
              (st.fault.empty() ? std::string() : "; Status.fault: " + st.fault);
  svc.stop();
  if (svc.error()) o.problem("the service ended with: " + *svc.error());
  o.runs_after = completed_runs(dir).size();  // the runs removed were the operator's to remove
  account(o, dir, svc.last());
  return o;
}

FaultOutcome wall_clock_steps_back() {
  FaultOutcome o;
  o.fault = "wall clock stepped back: the next run ids are taken";
  Scratch s("clock");
  const fs::path dir = s.dir / "runs";
  daemon::DaemonConfig c = base_config(dir);
  c.source.sim_repeat_program = false;  // one measurement, then the source ends
  std::string first_index;
  {
    ServiceThread probe(c);  // the simulated measurement starts at the same sample every time
    probe.wait_for([](const auto& st) { return !st.last_result.empty(); }, 60s);
    probe.stop();
    const auto runs = completed_runs(dir);
    if (runs.size() != 1) {
      o.problem("the probe run did not produce one run");
      return o;
    }
    const std::string id = runs[0].filename().string();
    first_index = id.substr(id.rfind('-') + 1);
    fs::remove_all(dir);
  }
  // Runs "from before the step": an id for every second of the next two minutes.
  fs::create_directories(dir);
  const std::time_t now = std::time(nullptr);
  for (int k = -5; k < 120; ++k) {
    const std::time_t t = now + k;
    std::tm tm{};
    gmtime_r(&t, &tm);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
    const fs::path run = dir / ("eicald-" + std::string(stamp) + "-" + first_index);
    fs::create_directories(run);
    std::ofstream(run / "earlier.txt") << "an earlier run " << k << "\n";
  }
  const Snapshot before = snapshot(dir);
  o.runs_before = runs_in(before);
  ServiceThread svc(c);
  o.service_alive = svc.wait_for([](const auto& st) { return st.results_written >= 1; }, 60s);
  svc.stop();
  if (svc.error()) o.problem("the service ended with: " + *svc.error());
  o.runs_intact = intact_runs(before, dir);
  const std::string last = svc.last().last_result;
  const std::string id = fs::path(last).parent_path().filename().string();
  o.outcome = "the new run gets a free id (" + id.substr(id.size() > 12 ? id.size() - 12 : 0) + "), none is replaced";
  o.flagged = false;
  std::error_code ec;
  std::size_t fresh = 0;
  for (const auto& r : completed_runs(dir)) fresh += fs::exists(r / "run.toml", ec) ? 1 : 0;
  o.runs_after = fresh;
  if (fresh != 1) o.problem("expected exactly one new run with run.toml, found " + std::to_string(fresh));
  o.clean = temporaries(dir).empty();
  o.measurements_lost = static_cast<std::int64_t>(svc.last().measurements) - static_cast<std::int64_t>(fresh);
  o.data_lost = o.measurements_lost == 0 ? "0" : std::to_string(o.measurements_lost) + " measurements not recorded";
  return o;
}

}  // namespace eical::faults
