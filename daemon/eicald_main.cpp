// eicald: the embedded inertial calibrator service. Reads /etc/eical/eicald.toml (or
// --config), acquires continuously from the configured source, runs a measurement for
// every M101..M103 of the NC program, writes each as an eical-run/1 directory with its
// result.json, and reports to systemd (READY, STATUS, WATCHDOG, STOPPING).
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/service.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "daemon/system/log.hpp"
#include "daemon/system/notify.hpp"
#include "drivers/source/source.hpp"
#include "dsp/core/error.hpp"

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <thread>

namespace {

std::atomic<bool> g_stop{false};

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

  DaemonConfig config;
  try {
    config = load_daemon_config(config_file);
  } catch (const std::exception& e) {
    log(LogLevel::error, "configuration: %s", e.what());
    return 2;
  }
  if (check) {
    try {
      auto source = Service::make_source(config);
      source->open();
      if (!config.calibration_file.empty()) {
        const auto cal = eical::drivers::read_sensor_calibration(config.calibration_file, source->meta());
        std::printf("%s: calibration %s (%s, from run %s) reads\n", config_file.c_str(), config.calibration_file.c_str(), cal.method.c_str(),
                    cal.run_id.c_str());
      }
      std::printf("%s: configuration valid; source '%.*s' opens\n", config_file.c_str(), static_cast<int>(source->name().size()),
                  source->name().data());
      return 0;
    } catch (const std::exception& e) {
      log(LogLevel::error, "source: %s", e.what());
      return 3;
    }
  }

  struct sigaction sa{};
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
      if (!ready) notifier.ready(line), ready = true;
      else notifier.status(line);
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
