#pragma once
// eicald's service in this process (daemon::Service on a thread of its own), as eicald's
// main runs it, with every Status it reports kept for the fault cases: the base
// configuration is the simulated machine with its triggers on the DAQ's frame channel, a
// DDS domain of the case's own on the loopback configuration, no real-time privileges.
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/service.hpp"

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace eical::faults {

daemon::DaemonConfig base_config(const std::filesystem::path& recording_dir);

class ServiceThread {
 public:
  explicit ServiceThread(daemon::DaemonConfig config);
  ~ServiceThread();  // stop()
  ServiceThread(const ServiceThread&) = delete;
  ServiceThread& operator=(const ServiceThread&) = delete;

  // Sets the stop flag (SIGTERM's) and waits for the service to finish.
  void stop();
  [[nodiscard]] bool running() const { return !finished_.load(); }
  // The last Status (every counter) and how many were reported.
  [[nodiscard]] daemon::ServiceStatus last() const;
  // run() threw (a start-up error): its message.
  [[nodiscard]] std::optional<std::string> error() const;
  // Polls the last Status until `want` holds; false at the timeout or when the service ended.
  bool wait_for(const std::function<bool(const daemon::ServiceStatus&)>& want, std::chrono::milliseconds timeout) const;
  // From now on every Status is checked against `condition` as it comes; seen(): one held.
  void watch(std::function<bool(const daemon::ServiceStatus&)> condition);
  [[nodiscard]] bool seen() const;

 private:
  std::atomic<bool> stop_{false}, finished_{false};
  mutable std::mutex mu_;
  daemon::ServiceStatus last_;
  std::optional<std::string> error_;
  std::function<bool(const daemon::ServiceStatus&)> watch_;
  bool watched_ = false;
  std::thread thread_;
};

}  // namespace eical::faults
