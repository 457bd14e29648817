// The collector's unit file (systemd/eical-collect.service): systemd's own verifier accepts
// it, it restarts on failure, and its spool lies in the one path it may write.
#include <gtest/gtest.h>

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

std::string read_file(const fs::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

TEST(CollectUnit, RestartsAndSpoolsWhereItMayWrite) {
  const std::string unit = read_file(kUnit);
  ASSERT_FALSE(unit.empty());
  EXPECT_NE(unit.find("\nRestart=on-failure\n"), std::string::npos);
  EXPECT_NE(unit.find("\nProtectSystem=strict\n"), std::string::npos);
  EXPECT_NE(unit.find("\nReadWritePaths=/var/lib/eical-collect\n"), std::string::npos);
  EXPECT_NE(unit.find("--spool /var/lib/eical-collect/spool"), std::string::npos);
  EXPECT_NE(unit.find("\nEnvironmentFile=/etc/eical/collect.env\n"), std::string::npos);  // EICAL_HISTORY_DB
}

TEST(CollectUnit, PassesSystemdAnalyzeVerify) {
  ASSERT_EQ(std::system("command -v systemd-analyze >/dev/null 2>&1"), 0)
      << "systemd-analyze not installed (scripts/deps.sh test)";
  const fs::path dir = fs::temp_directory_path() / ("eical-collect-unit-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  std::string unit = read_file(kUnit);
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
