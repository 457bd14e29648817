// eicald: the embedded inertial calibrator service. Reads /etc/eical/eicald.toml (or
// --config), acquires continuously from the configured source, runs a measurement for
// every M101..M103 of the NC program, writes each as an eical-run/1 directory with its
// result.json, and reports to systemd (READY, STATUS, WATCHDOG, STOPPING).
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/preflight.hpp"
#include "daemon/service/service.hpp"
#include "daemon/system/log.hpp"
#include "daemon/system/notify.hpp"
#include "daemon/triggers/trigger_input.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/source/source.hpp"
#include "dsp/core/error.hpp"

#include <CLI/CLI.hpp>

#include <malloc.h>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <thread>
#include <vector>

namespace {

std::atomic<bool> g_stop{false};

// --check: everything the service needs on this machine, each problem on its own line.
int check_config(const std::string& file, const eical::daemon::DaemonConfig& config) {
  using namespace eical::daemon;
  std::vector<std::string> problems, fine;
  try {
    auto source = Service::make_source(config);
    source->open();
    fine.push_back("source '" + std::string(source->name()) + "' opens");
    if (!config.calibration_file.empty()) {
      const auto cal = eical::drivers::read_sensor_calibration(config.calibration_file, source->meta());
      fine.push_back("calibration " + config.calibration_file.string() + " (" + cal.method + ", from run " +
                     cal.run_id + ") reads");
    }
  } catch (const std::exception& e) {
    problems.push_back(std::string("source: ") + e.what());
  }
  for (const auto& kind : config.triggers.inputs) {  // each device on its own: every absent one is named
    TriggerConfig one = config.triggers;
    one.inputs = {kind};
    try {
      for (const auto& input : open_trigger_inputs(one)) fine.push_back("trigger input " + input->name() + " opens");
    } catch (const std::exception& e) {
      problems.push_back(std::string("triggers: ") + e.what() + " ([triggers] inputs)");
    }
  }
  for (auto problem :
       {recording_dir_problem(config.recording.dir), dds_config_problem(config.dds), setpoint_problem(config.setpoint)})
    if (problem) problems.push_back(*problem);
  for (const auto& p : problems) log(LogLevel::error, "%s: %s", file.c_str(), p.c_str());
  if (!problems.empty()) return 3;
  std::string summary;
  for (const auto& f : fine) summary += "; " + f;
  std::printf("%s: configuration valid%s; recording path %s writable\n", file.c_str(), summary.c_str(),
              config.recording.dir.c_str());
  return 0;
}

extern "C" void on_signal(int) { g_stop.store(true); }

}  // namespace

int main(int argc, char** argv) {
  using namespace eical::daemon;
  CLI::App app{"eicald - embedded inertial calibrator service"};
  std::string config_file = "/etc/eical/eicald.toml";
  bool check = false;
  app.add_option("-c,--config", config_file, "configuration file (config/eicald.toml documents every key)");
  app.add_flag("--check", check, "validate the configuration and the source, then exit");
  CLI11_PARSE(app, argc, argv);
  // Buffers above 256 kB (a long recording's evaluation) are mapped and go back to the
  // system when freed, not kept in the heap by glibc's adaptive threshold.
  mallopt(M_MMAP_THRESHOLD, 256 * 1024);

  DaemonConfig config;
  try {
    config = load_daemon_config(config_file);
  } catch (const std::exception& e) {
    log(LogLevel::error, "configuration: %s", e.what());
    return 2;
  }
  if (check) return check_config(config_file, config);

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);

  const SystemdNotifier notifier;
  std::atomic<bool> running{true};
  // The watchdog is fed from its own thread only while the DSP loop reports progress.
  std::atomic<std::uint64_t> heartbeat{0};
  std::thread watchdog([&] {
    if (!notifier.watchdog_interval()) return;
    std::uint64_t last = 0;
    while (running.load()) {
      std::this_thread::sleep_for(*notifier.watchdog_interval());
      const auto now = heartbeat.load();
      if (now != last) notifier.watchdog();  // a stalled DSP loop lets systemd restart us
      last = now;
    }
  });
  int rc = 0;
  try {
    Service service(config);
    bool ready = false;
    service.run(g_stop, [&](const ServiceStatus& s) {
      heartbeat.fetch_add(1);
      char line[256];
      std::snprintf(line, sizeof line, "%s, %llu frames, %llu overruns, %llu lost, %llu results%s%s", s.state.c_str(),
                    static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.overruns),
                    static_cast<unsigned long long>(s.frames_lost), static_cast<unsigned long long>(s.results_written),
                    s.fault.empty() ? "" : "; last error: ", s.fault.c_str());
      if (!ready)
        notifier.ready(line), ready = true;
      else
        notifier.status(line);
    });
  } catch (const eical::drivers::SourceError& e) {
    log(LogLevel::error, "source: %s", e.what());
    rc = 3;
  } catch (const std::exception& e) {
    log(LogLevel::error, "%s", e.what());
    rc = 1;
  }
  notifier.stopping();
  running.store(false);
  watchdog.join();
  return rc;
}
