// Faults on the HMI bus: an HMI flooding Command at 1 kHz, and malformed or oversized
// Commands (times that are not CLOCK_MONOTONIC, codes and actions that do not exist, names
// of hundreds of kilobytes). The service runs in this process with its DDS link; the case
// is the HMI (and, for the malformed ones, the NC: triggers over DDS only).
#include "tests/faults/harness/fault_cases.hpp"
#include "tests/faults/harness/recording_dir.hpp"
#include "tests/faults/harness/service_thread.hpp"

#include "drivers/dds/bus.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <climits>
#include <cstdint>
#include <ctime>
#include <limits>
#include <set>

namespace eical::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using drivers::dds::CommandMsg;

std::int64_t clock_ns(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// What eicald writes to stderr (its journal) while the object lives, in a file.
class JournalCapture {
 public:
  explicit JournalCapture(const fs::path& file) : file_(file) {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::close(fd);
  }
  ~JournalCapture() { restore(); }
  JournalCapture(const JournalCapture&) = delete;
  JournalCapture& operator=(const JournalCapture&) = delete;
  std::string restore() {
    if (saved_ >= 0) std::fflush(stderr), ::dup2(saved_, 2), ::close(saved_), saved_ = -1;
    return slurp(file_);
  }

 private:
  fs::path file_;
  int saved_ = -1;
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Collects every Reply of the bus on a thread of its own, by request id.
class ReplyCollector {
 public:
  explicit ReplyCollector(drivers::dds::Bus& bus) : bus_(bus), thread_([this] { run(); }) {}
  ~ReplyCollector() {
    stop_ = true;
    bus_.wake();
    thread_.join();
  }
  std::map<std::uint32_t, drivers::dds::ReplyMsg> replies() const {
    std::lock_guard lk(mu_);
    return replies_;
  }

 private:
  void run() {
    while (!stop_)
      if (auto r = bus_.take_reply(100ms)) {
        std::lock_guard lk(mu_);
        replies_[r->request_id] = *r;
      }
  }
  drivers::dds::Bus& bus_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mu_;
  std::map<std::uint32_t, drivers::dds::ReplyMsg> replies_;
  std::thread thread_;
};

bool wait_reply(const ReplyCollector& c, std::uint32_t id, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    if (c.replies().count(id)) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

}  // namespace

FaultOutcome command_flood() {
  FaultOutcome o;
  o.fault = "HMI flooding Command at 1 kHz for 5 s";
  Scratch s("flood");
  const fs::path dir = s.dir / "runs";
  daemon::DaemonConfig c = base_config(dir);
  c.source.pacing = "realtime";  // the flood competes with real-time acquisition
  c.triggers.inputs = {"frame", "dds"};
  JournalCapture journal(s.dir / "journal.txt");
  ServiceThread svc(c);
  drivers::dds::Bus hmi(c.dds.domain_id, drivers::dds::Role::hmi);
  ReplyCollector replies(hmi);
  // The bus is up when a ping is answered.
  std::uint32_t id = 0;
  CommandMsg cmd;
  cmd.sender = "flooding-hmi";
  cmd.action = "ping";
  bool up = false;
  for (int i = 0; i < 100 && !up; ++i) cmd.request_id = ++id, hmi.send(cmd), up = wait_reply(replies, id, 200ms);
  if (!up) o.problem("no Reply before the flood: the bus did not come up");
  const daemon::ServiceStatus before = svc.last();
  const std::uint32_t first = id + 1;
  const auto t0 = Clock::now();
  std::size_t sent = 0;
  for (int k = 0; k < 5000; ++k) {
    cmd.request_id = ++id;
    cmd.action = k % 10 == 9 ? "trigger" : "ping";
    cmd.code = k % 10 == 9 ? 999 : 0;  // a trigger code that is no NC trigger: refused, no measurement touched
    sent += hmi.send(cmd) ? 1 : 0;
    std::this_thread::sleep_until(t0 + std::chrono::microseconds(1000 * (k + 1)));
  }
  const double flood_s = std::chrono::duration<double>(Clock::now() - t0).count();
  // Right after the flood: how long until a command is answered again.
  const auto t1 = Clock::now();
  cmd.request_id = ++id, cmd.action = "ping", cmd.code = 0;
  hmi.send(cmd);
  if (wait_reply(replies, id, 5s))
    o.recovery_s = std::chrono::duration<double>(Clock::now() - t1).count();
  else
    o.problem("no Reply right after the flood");
  std::this_thread::sleep_for(1s);
  const auto answered_now = replies.replies();
  std::size_t answered = 0;
  for (const auto& [rid, r] : answered_now) answered += rid >= first ? 1 : 0;
  const std::uint64_t results_before = svc.last().results_written;
  o.service_alive = svc.wait_for([&](const auto& st) { return st.results_written > results_before; }, 60s);
  const daemon::ServiceStatus after = svc.last();
  svc.stop();
  const std::string log = journal.restore();
  const std::size_t lines = count(log, "command from flooding-hmi");
  const std::uint64_t overruns = after.overruns - before.overruns,
                      commands = after.counters.commands - before.counters.commands;
  o.flagged = false;
  o.clean = temporaries(dir).empty() && overruns == 0;
  if (overruns > 0) o.problem(std::to_string(overruns) + " frames overran the ring during the flood");
  if (answered < sent / 2)
    o.problem("only " + std::to_string(answered) + " of " + std::to_string(sent) + " commands answered");
  if (lines > 20) o.problem(std::to_string(lines) + " journal lines for the flood");
  char b[300];
  std::snprintf(b, sizeof b,
                "%zu sent in %.1f s, %llu received, %zu answered; ring overruns %llu; %zu journal lines (then counted)",
                sent, flood_s, static_cast<unsigned long long>(commands), answered,
                static_cast<unsigned long long>(overruns), lines);
  o.outcome = b;
  o.runs_after = completed_runs(dir).size();
  for (const auto& r : completed_runs(dir)) {
    std::string why;
    if (!readable_with_result(r, &why)) o.problem("not readable: " + why);
  }
  o.measurements_lost =
      static_cast<std::int64_t>(svc.last().measurements) - static_cast<std::int64_t>(svc.last().results_written);
  o.data_lost = o.measurements_lost == 0 ? "0" : std::to_string(o.measurements_lost) + " measurements not recorded";
  return o;
}

FaultOutcome malformed_commands() {
  FaultOutcome o;
  o.fault = "malformed and oversized Commands (wall-clock times, unknown codes, 256 KiB names)";
  Scratch s("malformed");
  const fs::path dir = s.dir / "runs";
  daemon::DaemonConfig c = base_config(dir);
  c.source.pacing = "realtime";
  c.triggers.inputs = {"dds"};  // the NC's M-codes come over DDS only
  JournalCapture journal(s.dir / "journal.txt");
  ServiceThread svc(c);
  drivers::dds::Bus nc(c.dds.domain_id, drivers::dds::Role::hmi);
  ReplyCollector replies(nc);
  std::uint32_t id = 0;
  CommandMsg ping;
  ping.sender = "nc";
  ping.action = "ping";
  bool up = false;
  for (int i = 0; i < 100 && !up; ++i) ping.request_id = ++id, nc.send(ping), up = wait_reply(replies, id, 200ms);
  if (!up) o.problem("no Reply: the bus did not come up");
  std::this_thread::sleep_for(2500ms);  // frames flow: the DAQ clock is known
  // Every one of these must be refused with a Reply, and change nothing.
  std::vector<CommandMsg> bad;
  auto trig = [](int code, std::int64_t t_ns) {
    CommandMsg m;
    m.sender = "nc", m.action = "trigger", m.code = code, m.time_ns = t_ns;
    return m;
  };
  bad.push_back(trig(101, clock_ns(CLOCK_REALTIME)));  // wall-clock time: 1.7e18 ns ahead of the DAQ clock
  bad.push_back(trig(101, std::numeric_limits<std::int64_t>::max()));
  bad.push_back(trig(103, clock_ns(CLOCK_REALTIME)));
  for (int code : {0, -1, 999999, INT_MIN, INT_MAX}) bad.push_back(trig(code, 0));
  for (const char* action : {"", "\x01\x02\x7f\xff\xfe", "TRIGGER", "trigger ", "reset"}) {
    CommandMsg m = trig(101, 0);
    m.action = action;
    bad.push_back(m);
  }
  CommandMsg huge = trig(102, 0);
  huge.sender = std::string(256 * 1024, 'S');
  for (int k = 0; k < 20; ++k) bad.push_back(huge);
  CommandMsg long_action = trig(101, 0);
  long_action.action = std::string(64 * 1024, 'a');
  bad.push_back(long_action);
  std::set<std::uint32_t> bad_ids;
  // 10 ms apart: the Command topic keeps the last 16 (a burst beyond that is DDS's to drop).
  for (auto& m : bad) m.request_id = ++id, bad_ids.insert(id), nc.send(m), std::this_thread::sleep_for(10ms);
  std::size_t refused = 0, answered = 0;
  const auto end = Clock::now() + 10s;
  while (Clock::now() < end && answered < bad.size()) {
    answered = refused = 0;
    for (const auto& [rid, r] : replies.replies())
      if (bad_ids.count(rid)) ++answered, refused += r.ok ? 0 : 1;
    std::this_thread::sleep_for(20ms);
  }
  if (answered < bad.size()) o.problem(std::to_string(bad.size() - answered) + " malformed commands got no Reply");
  if (refused < answered) o.problem(std::to_string(answered - refused) + " malformed commands were accepted");
  // Then the NC measures as usual: M101 now, M103 a second later, a result.
  CommandMsg m101 = trig(101, clock_ns(CLOCK_MONOTONIC)), m103 = trig(103, 0);
  m101.request_id = ++id;
  nc.send(m101);
  const bool got101 = wait_reply(replies, id, 3s);
  const bool ok101 = got101 && replies.replies().at(id).ok;
  if (!ok101)
    o.problem("the NC's M101 after the malformed commands was refused: " +
              (got101 ? replies.replies().at(id).message : std::string("no Reply")));
  std::this_thread::sleep_for(1s);
  m103.time_ns = clock_ns(CLOCK_MONOTONIC), m103.request_id = ++id;
  nc.send(m103);
  (void)wait_reply(replies, id, 3s);
  o.service_alive = ok101 && svc.wait_for([](const auto& st) { return st.results_written >= 1; }, 60s);
  // Nothing to recover from: the service never stopped answering (recovery: -).
  svc.stop();
  const std::string log = journal.restore();
  std::size_t longest = 0;
  for (std::size_t a = 0, b; a < log.size(); a = b + 1) {
    b = log.find('\n', a);
    if (b == std::string::npos) b = log.size();
    longest = std::max(longest, b - a);
  }
  if (longest > 2000) o.problem("a journal line of " + std::to_string(longest) + " bytes");
  o.flagged = refused == bad.size();  // each one refused, with its reason in the Reply
  o.clean = temporaries(dir).empty();
  o.outcome = std::to_string(refused) + " of " + std::to_string(bad.size()) +
              " refused with a Reply; longest journal line " + std::to_string(longest) +
              " bytes; the NC's next M101/M103 measured";
  o.runs_after = completed_runs(dir).size();
  o.measurements_lost =
      static_cast<std::int64_t>(svc.last().measurements) - static_cast<std::int64_t>(svc.last().results_written);
  o.data_lost = o.measurements_lost == 0 ? "0" : std::to_string(o.measurements_lost) + " measurements not recorded";
  return o;
}

}  // namespace eical::faults
