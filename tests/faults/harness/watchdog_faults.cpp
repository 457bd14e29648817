// The DSP thread hung: eicald stops feeding systemd's watchdog, systemd ends it (SIGABRT,
// its WatchdogSignal) and starts it again, and the new eicald says why. The case plays
// systemd: eicald runs as a child process with NOTIFY_SOCKET (a datagram socket of the
// case's own) and WATCHDOG_USEC set, as systemd starts a Type=notify unit with WatchdogSec.
#include "tests/faults/harness/eicald_process.hpp"
#include "tests/faults/harness/fault_cases.hpp"
#include "tests/faults/harness/recording_dir.hpp"

#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <thread>

namespace eical::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr auto kWatchdog = 3s;  // WatchdogSec of the emulated unit (eicald.service: 5 s)

// systemd's end of sd_notify: READY, STATUS and WATCHDOG datagrams, with their times.
class NotifySocket {
 public:
  explicit NotifySocket(const fs::path& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) ::close(fd_), fd_ = -1;
    timeval tv{0, 20000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~NotifySocket() {
    if (fd_ >= 0) ::close(fd_);
    std::error_code ec;
    fs::remove(path_, ec);
  }
  [[nodiscard]] bool ok() const { return fd_ >= 0; }
  // Reads what arrived (up to 20 ms); remembers the last READY, STATUS and WATCHDOG.
  void poll() {
    char buf[4096];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf - 1, 0);
      if (n <= 0) return;
      const std::string msg(buf, static_cast<std::size_t>(n));
      const auto now = Clock::now();
      if (msg.find("WATCHDOG=1") != std::string::npos) last_ping = now, ++pings;
      if (msg.find("READY=1") != std::string::npos) ready = true, ready_at = now;
      if (const auto at = msg.find("STATUS="); at != std::string::npos)
        status = msg.substr(at + 7, msg.find('\n', at) - at - 7);
    }
  }
  bool ready = false;
  Clock::time_point ready_at{}, last_ping{};
  int pings = 0;
  std::string status;

 private:
  fs::path path_;
  int fd_ = -1;
};

std::vector<std::pair<std::string, std::string>> systemd_env(const fs::path& socket) {
  return {{"NOTIFY_SOCKET", socket.string()},
          {"WATCHDOG_USEC", std::to_string(std::chrono::microseconds(kWatchdog).count())}};
}

}  // namespace

FaultOutcome dsp_thread_hung() {
  FaultOutcome o;
  o.fault = "DSP thread hung (watchdog, systemd restart)";
  Scratch s("watchdog");
  const fs::path dir = s.dir / "runs";
  fs::create_directories(dir);
  NotifySocket systemd(s.dir / "notify");
  if (!systemd.ok()) {
    o.problem("cannot bind the notify socket");
    return o;
  }
  // The hang comes at sample time 12 s, after a few measurements of the free-running simulator.
  fs::create_directories(s.dir / "hang");
  fs::create_directories(s.dir / "normal");
  const fs::path hang = write_eicald_config(s.dir / "hang", dir, "[source.fault]\nhang_dsp_at_s = 12.0\n");
  const fs::path normal = write_eicald_config(s.dir / "normal", dir);
  Clock::time_point killed;
  Snapshot before;
  std::string first_log;
  {
    EicaldProcess eicald(hang, s.dir / "eicald-1.log", systemd_env(s.dir / "notify"));
    rlimit no_core{0, 0};
    ::prlimit(eicald.pid(), RLIMIT_CORE, &no_core, nullptr);  // SIGABRT below: no core file
    const auto end = Clock::now() + 90s;
    // systemd: a unit whose watchdog is not fed for WatchdogSec gets SIGABRT.
    while (Clock::now() < end && eicald.running()) {
      systemd.poll();
      if (systemd.pings > 0 && Clock::now() - systemd.last_ping > kWatchdog) break;
    }
    if (!(systemd.pings > 0 && Clock::now() - systemd.last_ping > kWatchdog)) {
      o.problem("the watchdog was fed on (" + std::to_string(systemd.pings) +
                " pings) or never: eicald did not stall it");
      return o;
    }
    before = snapshot(dir);
    eicald.signal(SIGABRT);
    killed = Clock::now();
    const auto rc = eicald.wait_exit(10s);
    if (rc != 128 + SIGABRT)
      o.problem("eicald did not end by SIGABRT: " + (rc ? std::to_string(*rc) : std::string("still running")));
    first_log = eicald.log();
  }
  o.runs_before = runs_in(before);
  if (o.runs_before == 0) o.problem("no measurement was completed before the hang");
  if (first_log.find("the DSP thread has handled no frame") == std::string::npos)
    o.problem("the hung eicald did not log the stall");
  // systemd's Restart=on-failure: the same unit again (RestartSec=2s not waited here).
  systemd.ready = false, systemd.status.clear();
  EicaldProcess again(normal, s.dir / "eicald-2.log", systemd_env(s.dir / "notify"));
  const auto end = Clock::now() + 60s;
  while (Clock::now() < end && again.running() && !systemd.ready) systemd.poll();
  if (systemd.ready) o.recovery_s = std::chrono::duration<double>(systemd.ready_at - killed).count();
  const std::string said = systemd.status;
  o.flagged = said.find("did not stop cleanly") != std::string::npos && said.find("DSP thread") != std::string::npos;
  if (!o.flagged) o.problem("the restarted eicald's STATUS does not say why: " + said);
  // systemd reads every notification (a full socket would block sd_notify): so does the case.
  while (Clock::now() < end && again.running() && completed_runs(dir).size() <= o.runs_before) systemd.poll();
  o.service_alive = completed_runs(dir).size() > o.runs_before;
  again.signal(SIGTERM);
  const auto stop_end = Clock::now() + 20s;
  while (Clock::now() < stop_end && again.running()) systemd.poll();
  if (const auto rc = again.wait_exit(1s); rc != 0)
    o.problem("the restarted eicald did not stop cleanly (" +
              (rc ? "exit " + std::to_string(*rc) : std::string("still running")) +
              "): " + again.log().substr(again.log().size() > 600 ? again.log().size() - 600 : 0));
  o.runs_intact = intact_runs(before, dir);
  o.runs_after = completed_runs(dir).size() - o.runs_before;
  o.clean = temporaries(dir).empty();
  const auto at = said.find("the DSP thread");
  o.outcome = "watchdog starved, SIGABRT; the next start's STATUS: \"" +
              (at == std::string::npos ? said : said.substr(at, 60)) + "...\"";
  o.measurements_lost = 1;
  o.data_lost = "at most the measurement under way at the hang (in the hung process's memory)";
  return o;
}

}  // namespace eical::faults
