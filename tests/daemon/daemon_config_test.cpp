#include "daemon/config/daemon_config.hpp"
#include "dsp/core/error.hpp"
#include "tests/support/text_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using eical::daemon::load_daemon_config;

const fs::path kExample = fs::path(EICAL_SOURCE_DIR) / "config" / "eicald.toml";

fs::path write_temp(const std::string& text) {
  std::random_device rd;
  const fs::path p = fs::temp_directory_path() / ("eicald-test-" + std::to_string(rd()) + ".toml");
  std::ofstream(p) << text;
  return p;
}

using test_support::slurp;

// The error message for `text`, or "" when it loads.
std::string error_of(const std::string& text) {
  const fs::path p = write_temp(text);
  std::string msg;
  try {
    (void)load_daemon_config(p);
  } catch (const eical::dsp::InputError& e) {
    msg = e.what();
  }
  fs::remove(p);
  return msg;
}

TEST(DaemonConfig, DocumentedExampleLoadsWithItsValues) {
  const auto c = load_daemon_config(kExample);
  EXPECT_EQ(c.source.kind, "sim");
  EXPECT_EQ(c.source.sim_repeats, 5);
  EXPECT_EQ(c.triggers.can_id, 0x1E0u);
  ASSERT_EQ(c.psd.size(), 2u);
  EXPECT_EQ(c.psd[1].measures, "y");
  EXPECT_DOUBLE_EQ(c.psd[1].center_mm[0], 10.0);
  EXPECT_DOUBLE_EQ(c.sensors[1].k1_v_per_g[2], 1.234);
  EXPECT_EQ(c.limits.ring_capacity_frames, 65536u);
}

TEST(DaemonConfig, UnknownKeyNamesLineAndKey) {
  // A typo on line 3 of the file.
  const auto msg = error_of("[source]\nkind = \"sim\"\npacingg = \"realtime\"\n");
  EXPECT_NE(msg.find(":3:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("source.pacingg"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

TEST(DaemonConfig, WrongTypeNamesKeyAndType) {
  const auto msg = error_of("[acquisition]\nfs_hz = \"fast\"\n");
  EXPECT_NE(msg.find(":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("acquisition.fs_hz"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got string"), std::string::npos) << msg;
}

TEST(DaemonConfig, OutOfRangeAndInvalidValuesAreRefused) {
  EXPECT_NE(error_of("[limits]\nring_capacity_frames = 1000\n").find("power of two"), std::string::npos);
  EXPECT_NE(error_of("[source]\nkind = \"replay\"\n").find("replay_run"), std::string::npos);
  EXPECT_NE(error_of("[source]\nkind = \"serial\"\n").find("not one of"), std::string::npos);
  EXPECT_NE(error_of("[triggers]\ninputs = [\"frame\", \"pigeon\"]\n").find("pigeon"), std::string::npos);
  EXPECT_NE(error_of("[sensors.head]\nto_machine = [[1,0,0],[0,0,0],[0,0,1]]\n").find("singular"), std::string::npos);
  EXPECT_NE(error_of("[sensors.head]\nzeta = -0.1\n").find("sensors.head.zeta"), std::string::npos);
  EXPECT_NE(error_of("[machine]\ntable_axes = [\"x\"]\nhead_axes = [\"x\"]\n").find("both"), std::string::npos);
  // Accepted, it would do nothing: every lost frame degrades the result.
  EXPECT_NE(error_of("[limits]\nmax_lost_frames = 3\n").find("only 0"), std::string::npos);
  EXPECT_NE(error_of("[limits]\ntemp_min_c = 40.0\ntemp_max_c = 30.0\n").find("temp_max_c"), std::string::npos);
  // Accepted, the strips beyond a frame's 16 would be left out of every recording.
  std::string seventeen = "[triggers]\ninputs = [\"frame\"]\n";
  for (int k = 0; k < 17; ++k) seventeen += "[[psd]]\nmeasures = \"x\"\ncenter_mm = [0.0, 0.0]\n";
  EXPECT_NE(error_of(seventeen).find("17 strips, at most 16"), std::string::npos) << error_of(seventeen);
}

TEST(DaemonConfig, SyntaxErrorNamesLineAndColumn) {
  const auto msg = error_of("[dds]\ndomain_id = = 3\n");
  EXPECT_NE(msg.find(":2:"), std::string::npos) << msg;
}

TEST(DaemonConfig, EveryKeyOfTheExampleIsRecognised) {
  // Misspelling any one key of the example must be refused (as unknown, or as a missing
  // required key): proves the example documents no key the loader silently ignores.
  const std::string text = slurp(kExample);
  std::size_t pos = 0;
  int checked = 0;
  while ((pos = text.find('\n', pos)) != std::string::npos) {
    ++pos;
    if (pos >= text.size() || text[pos] == '#' || text[pos] == '[' || text[pos] == '\n') continue;
    const auto eq = text.find(" = ", pos);
    if (eq == std::string::npos || text.find('\n', pos) < eq) continue;
    std::string typo = text;
    typo.insert(eq, "_typo");
    const auto msg = error_of(typo);
    const bool refused =
        msg.find("unknown key") != std::string::npos || msg.find("required key is missing") != std::string::npos;
    EXPECT_TRUE(refused) << "key at offset " << pos << ": " << msg;
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

// In every table of the example (and at its root), an unknown key is refused naming the
// file, its line and the key; a key of the extension namespace (ext_, docs/run-files.md) is
// passed over.
TEST(DaemonConfig, UnknownKeyInEveryTableNamesFileLineAndKeyExtensionPassesOver) {
  const std::string text = slurp(kExample);
  std::vector<std::size_t> after = {0};  // offsets of the lines a key goes after: the root's first
  for (std::size_t pos = 0; (pos = text.find("\n[", pos)) != std::string::npos; ++pos)
    after.push_back(text.find('\n', pos + 1) + 1);
  ASSERT_GT(after.size(), 8u);
  for (const std::size_t at : after) {
    const auto line =
        static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n')) + 1;
    for (const std::string key : {"typo_key", "ext_note"}) {
      std::string edited = text;
      edited.insert(at, key + " = 1\n");
      const fs::path p = write_temp(edited);
      std::string msg;
      try {
        (void)load_daemon_config(p);
      } catch (const eical::dsp::InputError& e) {
        msg = e.what();
      }
      fs::remove(p);
      if (key == "ext_note") {
        EXPECT_EQ(msg, "") << "line " << line;
      } else {
        EXPECT_NE(msg.find(p.string() + ":" + std::to_string(line) + ": "), std::string::npos) << msg;
        EXPECT_NE(msg.find("typo_key: unknown key"), std::string::npos) << msg;
      }
    }
  }
}

}  // namespace
