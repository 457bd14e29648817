// sd_notify as systemd sees it: the test plays systemd's side of NOTIFY_SOCKET.
#include "daemon/system/notify.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

namespace {

TEST(SystemdNotify, ReadyStatusWatchdogAndStoppingReachTheNotifySocket) {
  const std::string path = "/tmp/eical-notify-" + std::to_string(::getpid());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  path.copy(addr.sun_path, sizeof addr.sun_path - 1);
  ::unlink(path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "4000000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  const eical::daemon::SystemdNotifier n;
  EXPECT_TRUE(n.under_systemd());
  ASSERT_TRUE(n.watchdog_interval());
  EXPECT_EQ(n.watchdog_interval()->count(), 2000000);  // half of WatchdogSec
  n.ready("IDLE, 0 frames");
  n.watchdog();
  n.stopping();
  auto next = [&] {
    char buf[256];
    const ssize_t got = ::recv(fd, buf, sizeof buf - 1, MSG_DONTWAIT);
    return got > 0 ? std::string(buf, static_cast<std::size_t>(got)) : std::string();
  };
  EXPECT_EQ(next(), "READY=1\nSTATUS=IDLE, 0 frames");
  EXPECT_EQ(next(), "WATCHDOG=1");
  EXPECT_EQ(next(), "STOPPING=1");
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
  ::close(fd);
  ::unlink(path.c_str());
}

}  // namespace
