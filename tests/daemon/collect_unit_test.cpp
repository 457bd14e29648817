// The collector's unit file (systemd/eical-collect.service): systemd's own verifier accepts
// it, it restarts on failure, and its spool lies in the one path it may write.
#include <gtest/gtest.h>
#include "tests/support/text_file.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace {

namespace fs = std::filesystem;
const fs::path kUnit = fs::path(EICAL_SOURCE_DIR) / "systemd" / "eical-collect.service";

using test_support::slurp;

TEST(CollectUnit, RestartsAndSpoolsWhereItMayWrite) {
  const std::string unit = slurp(kUnit);
  ASSERT_FALSE(unit.empty());
  EXPECT_NE(unit.find("\nRestart=on-failure\n"), std::string::npos);
  EXPECT_NE(unit.find("\nProtectSystem=strict\n"), std::string::npos);
  EXPECT_NE(unit.find("\nReadWritePaths=/var/lib/eical-collect\n"), std::string::npos);
  EXPECT_NE(unit.find("--spool /var/lib/eical-collect/spool"), std::string::npos);
  EXPECT_NE(unit.find("\nEnvironmentFile=/etc/eical/collect.env\n"), std::string::npos);  // EICAL_HISTORY_DB
}

// As eicald's unit: systemd waits for READY=1 and restarts a collector whose loop stops
// feeding the watchdog (collect_notify_test.cpp sees both from the real binary).
TEST(CollectUnit, NotifiesSystemdAndHasAWatchdog) {
  const std::string unit = slurp(kUnit);
  EXPECT_NE(unit.find("\nType=notify\n"), std::string::npos);
  EXPECT_EQ(unit.find("\nType=simple\n"), std::string::npos);
  EXPECT_NE(unit.find("\nNotifyAccess=main\n"), std::string::npos);
  const auto at = unit.find("\nWatchdogSec=");
  ASSERT_NE(at, std::string::npos);
  const double watchdog_s = std::stod(unit.substr(at + 13));
  EXPECT_GT(watchdog_s, 0.6);  // above the loop's 300 ms receive, twice over
  // The stop waits for the spool to drain (10 s in cmd_collect.cpp) inside TimeoutStopSec.
  const auto stop = unit.find("\nTimeoutStopSec=");
  ASSERT_NE(stop, std::string::npos);
  EXPECT_GT(std::stod(unit.substr(stop + 16)), 10.0);
}

// Every long-running unit in systemd/ uses the notify protocol and a watchdog.
TEST(CollectUnit, EveryUnitInTheTreeNotifiesAndHasAWatchdog) {
  int units = 0;
  for (const auto& e : fs::directory_iterator(fs::path(EICAL_SOURCE_DIR) / "systemd")) {
    if (e.path().extension() != ".service") continue;
    ++units;
    const std::string unit = slurp(e.path());
    EXPECT_NE(unit.find("\nType=notify\n"), std::string::npos) << e.path();
    EXPECT_NE(unit.find("\nWatchdogSec="), std::string::npos) << e.path();
  }
  EXPECT_GE(units, 2);
}

TEST(CollectUnit, PassesSystemdAnalyzeVerify) {
  ASSERT_EQ(std::system("command -v systemd-analyze >/dev/null 2>&1"), 0)
      << "systemd-analyze not installed (scripts/deps.sh test)";
  const fs::path dir = fs::temp_directory_path() / ("eical-collect-unit-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  std::string unit = slurp(kUnit);
  const std::string exec = "/usr/local/bin/eical";  // verify wants an existing binary
  unit.replace(unit.find(exec), exec.size(), "/bin/true");
  const std::string env = "/etc/eical/collect.env";
  unit.replace(unit.find(env), env.size(), (dir / "collect.env").string());
  std::ofstream(dir / "collect.env") << "EICAL_HISTORY_DB=postgresql://eical@history-server/eical_history\n";
  std::ofstream(dir / "eical-collect.service") << unit;
  std::string output;
  FILE* p = ::popen(("systemd-analyze verify " + (dir / "eical-collect.service").string() + " 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) output += buf;
  const int rc = ::pclose(p);
  fs::remove_all(dir);
  EXPECT_EQ(rc, 0) << output;
  EXPECT_EQ(output.find("Unknown"), std::string::npos) << output;
}

}  // namespace
