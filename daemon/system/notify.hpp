#pragma once
// sd_notify for Type=notify units: READY, STATUS, WATCHDOG, STOPPING. Outside systemd
// (no NOTIFY_SOCKET) every call is a cheap no-op, so eicald also runs from a shell.
#include <chrono>
#include <optional>
#include <string>

namespace eical::daemon {

class SystemdNotifier {
 public:
  SystemdNotifier();
  [[nodiscard]] bool under_systemd() const { return under_systemd_; }
  // Interval at which watchdog() must be called (half of WatchdogSec), if enabled.
  [[nodiscard]] std::optional<std::chrono::microseconds> watchdog_interval() const { return watchdog_; }

  void ready(const std::string& status) const;
  void status(const std::string& status) const;
  void watchdog() const;
  void stopping() const;

 private:
  bool under_systemd_ = false;
  std::optional<std::chrono::microseconds> watchdog_;
};

}  // namespace eical::daemon
