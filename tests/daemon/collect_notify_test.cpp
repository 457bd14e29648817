// eical collect as systemd runs it (systemd/eical-collect.service, Type=notify with
// WatchdogSec): the test plays systemd's side of NOTIFY_SOCKET and sees READY=1 once the
// collector is up, WATCHDOG=1 from its receive loop at half the watchdog period, and
// STOPPING=1 at its end.
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

TEST(CollectNotify, ReadyThenWatchdogFromItsLoopThenStopping) {
#ifndef EICAL_CLI
  GTEST_SKIP() << "this build has no eical command line";
#else
  const fs::path dir = fs::temp_directory_path() / ("eical-collect-notify-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  const std::string path = (dir / "notify").string();
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof addr.sun_path);
  path.copy(addr.sun_path, sizeof addr.sun_path - 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const int domain = eical::drivers::dds::claim_free_domain();
  // WatchdogSec=1s: a ping every 0.5 s; the collector runs 3 s.
  const std::string cmd = "NOTIFY_SOCKET=" + path +
                          " WATCHDOG_USEC=1000000 CYCLONEDDS_URI=file://" EICAL_SOURCE_DIR
                          "/config/cyclonedds-loopback.xml " EICAL_CLI " collect --db " +
                          (dir / "history.sqlite").string() + " --spool " + (dir / "spool").string() + " --domain " +
                          std::to_string(domain) + " --timeout 3 > " + (dir / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::vector<std::string> got;
  char buf[512];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT)) > 0;)
    got.emplace_back(buf, static_cast<std::size_t>(n));
  ::close(fd);
  fs::remove_all(dir);
  ASSERT_GE(got.size(), 2u);
  EXPECT_EQ(got.front(), "READY=1\nSTATUS=collecting on DDS domain " + std::to_string(domain));
  EXPECT_EQ(got.back(), "STOPPING=1");
  std::size_t pings = 0;
  for (std::size_t i = 1; i + 1 < got.size(); ++i) {
    EXPECT_EQ(got[i], "WATCHDOG=1");
    ++pings;
  }
  // 3 s at one ping per 0.5 s, each up to one 300 ms receive late: about 5. At least two
  // (the loop feeds it again and again, even on a loaded host), never more than one a 0.5 s.
  EXPECT_GE(pings, 2u);
  EXPECT_LE(pings, 6u);
#endif
}

}  // namespace
