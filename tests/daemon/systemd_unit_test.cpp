// The unit file is part of the product: check it with systemd's own verifier and check
// that it agrees with the daemon's defaults (recording path writable, notify protocol).
#include "daemon/config/daemon_config.hpp"
#include "tests/support/text_file.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
const fs::path kUnit = fs::path(EICAL_SOURCE_DIR) / "systemd" / "eicald.service";

using test_support::slurp;

// Values of `key=` in the unit, in order (keys may repeat).
std::vector<std::string> values_of(const std::string& unit, const std::string& key) {
  std::vector<std::string> out;
  std::istringstream is(unit);
  for (std::string line; std::getline(is, line);)
    if (line.rfind(key + "=", 0) == 0) out.push_back(line.substr(key.size() + 1));
  return out;
}

std::set<std::string> words(const std::string& s) {
  std::istringstream is(s);
  return {std::istream_iterator<std::string>(is), std::istream_iterator<std::string>()};
}

TEST(SystemdUnit, DeclaresNotifyWatchdogRestartAndHardening) {
  const std::string unit = slurp(kUnit);
  ASSERT_FALSE(unit.empty());
  EXPECT_EQ(values_of(unit, "Type"), std::vector<std::string>{"notify"});
  ASSERT_EQ(values_of(unit, "WatchdogSec").size(), 1u);
  EXPECT_GT(std::stod(values_of(unit, "WatchdogSec")[0]), 0.0);
  EXPECT_EQ(values_of(unit, "Restart"), std::vector<std::string>{"on-failure"});
  EXPECT_EQ(values_of(unit, "ProtectSystem"), std::vector<std::string>{"strict"});
  EXPECT_EQ(values_of(unit, "NoNewPrivileges"), std::vector<std::string>{"yes"});
  // Exactly what SCHED_FIFO and mlockall need, nothing more, in both sets.
  const std::set<std::string> rt = {"CAP_SYS_NICE", "CAP_IPC_LOCK"};
  ASSERT_EQ(values_of(unit, "CapabilityBoundingSet").size(), 1u);
  EXPECT_EQ(words(values_of(unit, "CapabilityBoundingSet")[0]), rt);
  ASSERT_EQ(values_of(unit, "AmbientCapabilities").size(), 1u);
  EXPECT_EQ(words(values_of(unit, "AmbientCapabilities")[0]), rt);
}

TEST(SystemdUnit, RecordingDefaultIsWritableUnderTheSandbox) {
  const std::string unit = slurp(kUnit);
  const fs::path rec = eical::daemon::RecordingConfig{}.dir;  // default recording path
  const auto pos = unit.find("ReadWritePaths=");
  ASSERT_NE(pos, std::string::npos);
  const std::string rw = unit.substr(pos + 15, unit.find('\n', pos) - pos - 15);
  EXPECT_EQ(rec.string().rfind(rw, 0), 0u) << rec << " is not under ReadWritePaths=" << rw;
}

TEST(SystemdUnit, PassesSystemdAnalyzeVerify) {
  if (std::system("command -v systemd-analyze >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "systemd-analyze not installed; unit not verified";
  // verify checks that ExecStart exists: point it at a binary that does.
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("eicald-unit-" + std::to_string(rd()));
  fs::create_directories(dir);
  std::string unit = slurp(kUnit);
  const std::string exec = "/usr/bin/eicald";
  unit.replace(unit.find(exec), exec.size(), "/bin/true");
  std::ofstream(dir / "eicald.service") << unit;
  const std::string cmd = "systemd-analyze verify " + (dir / "eicald.service").string() + " 2>&1";
  std::string output;
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) output += buf;
  const int rc = ::pclose(p);
  fs::remove_all(dir);
  EXPECT_EQ(rc, 0) << output;
  EXPECT_EQ(output.find("Unknown"), std::string::npos) << output;
}

}  // namespace
