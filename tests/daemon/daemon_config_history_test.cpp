// [history] of eicald.toml: every key read and checked, a bad value refused naming the
// line and key, the installed example turning the history on.
#include "daemon/config/daemon_config.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::daemon::load_daemon_config;

std::string history_config_error(const std::string& text, eical::daemon::DaemonConfig* out = nullptr) {
  const fs::path p = fs::temp_directory_path() / ("eicald-history-" + std::to_string(std::random_device{}()) + ".toml");
  std::ofstream(p) << text;
  std::string msg;
  try {
    auto c = load_daemon_config(p);
    if (out) *out = c;
  } catch (const eical::dsp::InputError& e) {
    msg = e.what();
  }
  fs::remove(p);
  return msg;
}

TEST(DaemonConfigHistory, EveryKeyIsRead) {
  eical::daemon::DaemonConfig c;
  ASSERT_EQ(history_config_error("[history]\nenabled = true\ndb = \"postgresql://eical@server/eical\"\nspool_dir = "
                                 "\"/tmp/s\"\nretry_s = 5.0\n",
                                 &c),
            "");
  EXPECT_TRUE(c.history.enabled);
  EXPECT_EQ(c.history.db, "postgresql://eical@server/eical");
  EXPECT_EQ(c.history.spool_dir, "/tmp/s");
  EXPECT_EQ(c.history.retry_s, 5.0);
  ASSERT_EQ(history_config_error("", &c), "");
  EXPECT_FALSE(c.history.enabled);  // no [history]: no history kept
}

TEST(DaemonConfigHistory, BadValuesAreRefusedNamingTheKey) {
  EXPECT_NE(history_config_error("[history]\nretry_s = 0.0\n").find("retry_s"), std::string::npos);
  EXPECT_NE(history_config_error("[history]\ndb = \"\"\n").find("db"), std::string::npos);
  EXPECT_NE(history_config_error("[history]\nspool_dir = \"\"\n").find("spool_dir"), std::string::npos);
  EXPECT_NE(history_config_error("[history]\nenable = true\n").find("enable"),
            std::string::npos);  // a typo is not ignored
  EXPECT_NE(history_config_error("[history]\nenabled = \"yes\"\n").find("enabled"), std::string::npos);
  EXPECT_NE(
      history_config_error("[machine]\nname = \"\"\n[history]\nenabled = true\n").find("[machine] name is required"),
      std::string::npos);
}

TEST(DaemonConfigHistory, TheInstalledExampleKeepsAHistoryWhereTheServiceMayWrite) {
  const auto c = load_daemon_config(fs::path(EICAL_SOURCE_DIR) / "config" / "eicald.toml");
  EXPECT_TRUE(c.history.enabled);
  EXPECT_EQ(c.history.db, "/var/lib/eical/history.db");
  EXPECT_EQ(c.history.spool_dir, "/var/lib/eical/history-spool");
  // The unit's ProtectSystem=strict leaves only ReadWritePaths writable.
  std::ifstream unit(fs::path(EICAL_SOURCE_DIR) / "systemd" / "eicald.service");
  const std::string text{std::istreambuf_iterator<char>(unit), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find("\nReadWritePaths=/var/lib/eical\n"), std::string::npos);
  EXPECT_EQ(c.history.db.rfind("/var/lib/eical/", 0), 0u);
  EXPECT_EQ(c.history.spool_dir.string().rfind("/var/lib/eical/", 0), 0u);
}

}  // namespace
