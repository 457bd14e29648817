// Faults of the frames' source: a DAQ delivering faster than real time, and one stalling.
// The service runs in this process on [source] kind = "daq_stream" (the DAQ's wire
// protocol through a named pipe, the real decoder) fed by DaqFeeder; M-codes on the DAQ's
// trigger channel.
#include "tests/faults/harness/daq_feeder.hpp"
#include "tests/faults/harness/fault_cases.hpp"
#include "tests/faults/harness/recording_dir.hpp"
#include "tests/faults/harness/service_thread.hpp"

#include <nlohmann/json.hpp>

namespace eical::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

daemon::DaemonConfig daq_config(const fs::path& scratch) {
  daemon::DaemonConfig c = base_config(scratch / "runs");
  c.source.kind = "daq_stream";
  c.source.daq_stream.path = scratch / "daq.fifo";
  c.source.daq_stream.connect_timeout_s = 30.0;
  c.source.daq_stream.stall_timeout_s = 0.5;
  c.source.retry_s = 0.2;
  return c;
}

// By the flag's code (result-format.md, "Quality flags").
bool has_flag(const nlohmann::json& result, const std::string& code) {
  for (const auto& c : result["quality"]["flag_codes"])
    if (c == code) return true;
  return false;
}

// The runs with result.json, oldest first (ids carry the UTC second and the first sample).
std::vector<nlohmann::json> results(const fs::path& dir) {
  std::vector<std::pair<std::int64_t, nlohmann::json>> by_sample;
  for (const auto& r : completed_runs(dir)) {
    const std::string id = r.filename().string();
    if (!fs::exists(r / "result.json")) continue;
    by_sample.emplace_back(std::stoll(id.substr(id.rfind('-') + 1)), nlohmann::json::parse(slurp(r / "result.json")));
  }
  std::sort(by_sample.begin(), by_sample.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<nlohmann::json> out;
  for (auto& [k, j] : by_sample) out.push_back(std::move(j));
  return out;
}

void finish(FaultOutcome& o, ServiceThread& svc, const fs::path& dir) {
  svc.stop();
  if (svc.error()) o.problem("the service ended with: " + *svc.error());
  const daemon::ServiceStatus last = svc.last();
  o.clean = temporaries(dir).empty();
  o.runs_after = completed_runs(dir).size();
  for (const auto& r : completed_runs(dir)) {
    std::string why;
    if (!readable_with_result(r, &why)) o.problem("not readable: " + why);
  }
  o.measurements_lost = static_cast<std::int64_t>(last.measurements) - static_cast<std::int64_t>(last.results_written);
  o.data_lost = o.measurements_lost == 0 ? "0" : std::to_string(o.measurements_lost) + " measurements not recorded";
}

}  // namespace

FaultOutcome source_faster_than_real_time() {
  FaultOutcome o;
  o.fault = "DAQ delivering 3x faster than real time, then at its rate";
  Scratch s("fast");
  const fs::path dir = s.dir / "runs";
  ServiceThread svc(daq_config(s.dir));
  // 3x: 6 s of wall time at rest (the rate window fills), a circle; then real time: rest
  // (the window empties of the fast samples) and a circle.
  DaqFeeder daq(s.dir / "daq.fifo", {{daq_rest(18.0), 3.0},
                                     {daq_circle(1.0), 3.0},
                                     {daq_rest(5.0), 1.0},
                                     {daq_circle(1.0), 1.0},
                                     {daq_rest(1.0), 1.0}});
  svc.watch([](const auto& st) { return st.fault.find("source_rate") != std::string::npos; });
  if (!svc.wait_for([&](const auto&) { return daq.phase() >= 2; }, 60s))
    o.problem("the feeder did not get to real time");
  // Back at its rate from phase 2 on: when Status.fault no longer says source_rate.
  if (svc.wait_for([](const auto& st) { return st.fault.find("source_rate") == std::string::npos; }, 20s))
    o.recovery_s = std::chrono::duration<double>(Clock::now() - daq.phase_started(2)).count();
  if (!svc.wait_for([&](const auto&) { return daq.done(); }, 60s)) o.problem("the feeder did not finish");
  svc.wait_for([](const auto& st) { return st.results_written >= 2; }, 30s);
  const auto rs = results(dir);
  o.flagged =
      svc.seen() && !rs.empty() && has_flag(rs.front(), "source_rate") && rs.front()["quality"]["degraded"].get<bool>();
  if (!svc.seen()) o.problem("Status.fault never said source_rate");
  if (rs.size() < 2)
    o.problem("expected two measurements, got " + std::to_string(rs.size()));
  else if (!rs.front()["quality"]["flags"].dump().empty() && !has_flag(rs.front(), "source_rate"))
    o.problem("the fast measurement is not flagged source_rate: " + rs.front()["quality"]["flags"].dump());
  o.service_alive = rs.size() >= 2 && !has_flag(rs.back(), "source_rate");
  if (rs.size() >= 2 && has_flag(rs.back(), "source_rate"))
    o.problem("the measurement at the right rate is flagged source_rate too");
  o.outcome =
      "Status.fault source_rate (x3), the measurement flagged source_rate, degraded; the next one at the right rate "
      "unflagged";
  finish(o, svc, dir);
  if (o.recovery_s == o.recovery_s) o.outcome += " (Status clear after the 4 s rate window)";
  return o;
}

FaultOutcome source_stalls() {
  FaultOutcome o;
  o.fault = "DAQ stalls for 2 s mid-measurement";
  Scratch s("stall");
  const fs::path dir = s.dir / "runs";
  ServiceThread svc(daq_config(s.dir));
  std::vector<dsp::Frame> circle = daq_circle(1.0);
  const std::vector<dsp::Frame> first_half(circle.begin(),
                                           circle.begin() + static_cast<std::ptrdiff_t>(circle.size() / 2));
  DaqFeeder daq(s.dir / "daq.fifo", {{first_half, 1.0}, {{}, 1.0, 2.0}, {daq_circle(1.0), 1.0}, {daq_rest(1.0), 1.0}});
  svc.watch([](const auto& st) { return st.state == "FAULT"; });
  if (!svc.wait_for([&](const auto&) { return daq.phase() >= 2; }, 60s))
    o.problem("the feeder did not get past the stall");
  // Measuring again once the DAQ is back: the state leaves FAULT.
  if (svc.wait_for([](const auto& st) { return st.state != "FAULT"; }, 30s))
    o.recovery_s = std::chrono::duration<double>(Clock::now() - daq.phase_started(2)).count();
  svc.wait_for([&](const auto&) { return daq.done(); }, 60s);
  svc.wait_for([](const auto& st) { return st.results_written >= 2; }, 30s);
  const auto rs = results(dir);
  if (!svc.seen()) o.problem("Status never showed FAULT");
  if (rs.size() < 2) o.problem("expected two measurements, got " + std::to_string(rs.size()));
  o.flagged = svc.seen() && !rs.empty() && has_flag(rs.front(), "source_stopped") &&
              rs.front()["quality"]["degraded"].get<bool>();
  if (!rs.empty() && !has_flag(rs.front(), "source_stopped"))
    o.problem("the cut measurement is not flagged: " + rs.front()["quality"]["flags"].dump());
  o.service_alive = rs.size() >= 2 && !has_flag(rs.back(), "source_stopped");
  o.outcome =
      "FAULT (no bytes for 0.5 s), the source reopened every 0.2 s; the cut measurement recorded, flagged "
      "source_stopped";
  finish(o, svc, dir);
  return o;
}

}  // namespace eical::faults
