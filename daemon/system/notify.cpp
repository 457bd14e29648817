#include "daemon/system/notify.hpp"

#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace eical::daemon {

SystemdNotifier::SystemdNotifier() {
  under_systemd_ = std::getenv("NOTIFY_SOCKET") != nullptr;
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0)
    watchdog_ = std::chrono::microseconds(static_cast<std::int64_t>(usec / 2));
}

void SystemdNotifier::ready(const std::string& status) const {
  if (under_systemd_) sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str());
}

void SystemdNotifier::status(const std::string& status) const {
  if (under_systemd_) sd_notifyf(0, "STATUS=%s", status.c_str());
}

void SystemdNotifier::watchdog() const {
  if (under_systemd_) sd_notify(0, "WATCHDOG=1");
}

void SystemdNotifier::stopping() const {
  if (under_systemd_) sd_notify(0, "STOPPING=1");
}

}  // namespace eical::daemon
