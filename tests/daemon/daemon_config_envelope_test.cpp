// [envelope] of eicald.toml: read strictly, carried into the config, and the simulated NC's
// program checked against it at load.
#include "daemon/config/daemon_config.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace {

namespace fs = std::filesystem;
using eical::daemon::load_daemon_config;

// The error message for `text`, or "" when it loads; the config through `out` when it does.
std::string load(const std::string& text, eical::daemon::DaemonConfig* out = nullptr) {
  const fs::path p =
      fs::temp_directory_path() / ("eicald-envelope-" + std::to_string(std::random_device{}()) + ".toml");
  std::ofstream(p) << text;
  std::string msg;
  try {
    const auto c = load_daemon_config(p);
    if (out) *out = c;
  } catch (const eical::dsp::InputError& e) {
    msg = e.what();
  }
  fs::remove(p);
  return msg;
}

TEST(DaemonConfigEnvelope, DocumentedExampleHasTheDefaults) {
  const auto c = load_daemon_config(fs::path(EICAL_SOURCE_DIR) / "config" / "eicald.toml");
  const eical::dsp::WorkEnvelope d;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_DOUBLE_EQ(c.envelope.travel_mm[i][j], d.travel_mm[i][j]) << i << " " << j;
  EXPECT_DOUBLE_EQ(c.envelope.max_feed_mm_min, d.max_feed_mm_min);
  EXPECT_DOUBLE_EQ(c.envelope.max_accel_mm_s2, d.max_accel_mm_s2);
}

TEST(DaemonConfigEnvelope, ReadsEveryKey) {
  eical::daemon::DaemonConfig c;
  ASSERT_EQ(load("[envelope]\ntravel_x_mm = [0.0, 1200.0]\ntravel_y_mm = [-50, 700]\ntravel_z_mm = [-400.0, 20.0]\n"
                 "max_feed_mm_min = 40000\nmax_accel_mm_s2 = 5000.0\n[source.sim]\nprogram = \"step\"\n",
                 &c),
            "");
  EXPECT_DOUBLE_EQ(c.envelope.travel_mm[0][1], 1200.0);
  EXPECT_DOUBLE_EQ(c.envelope.travel_mm[1][0], -50.0);
  EXPECT_DOUBLE_EQ(c.envelope.travel_mm[2][0], -400.0);
  EXPECT_DOUBLE_EQ(c.envelope.max_feed_mm_min, 40000.0);
  EXPECT_DOUBLE_EQ(c.envelope.max_accel_mm_s2, 5000.0);
}

TEST(DaemonConfigEnvelope, UnknownKeyIsAnError) {
  const auto msg = load("[envelope]\nmax_feed_mm_mn = 40000\n");
  EXPECT_NE(msg.find("envelope.max_feed_mm_mn"), std::string::npos) << msg;
}

TEST(DaemonConfigEnvelope, TravelWithMinAboveMaxIsAnError) {
  const auto msg = load("[envelope]\ntravel_y_mm = [300.0, -300.0]\n");
  EXPECT_NE(msg.find("envelope.travel_y_mm"), std::string::npos) << msg;
  EXPECT_NE(msg.find("min below max"), std::string::npos) << msg;
}

TEST(DaemonConfigEnvelope, SimulatedCircleBeyondTheTravelIsRefused) {
  const auto msg = load("[envelope]\ntravel_x_mm = [-5.0, 5.0]\n[source.sim]\nradius_mm = 10.0\n");
  EXPECT_NE(msg.find("[source.sim]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("x = 10 mm, beyond the x travel -5..5 mm"), std::string::npos) << msg;
  EXPECT_NE(msg.find("travel_x_mm"), std::string::npos) << msg;
  // The same circle within a wider envelope loads.
  EXPECT_EQ(load("[envelope]\ntravel_x_mm = [-15.0, 15.0]\n[source.sim]\nradius_mm = 10.0\n"), "");
}

TEST(DaemonConfigEnvelope, SimulatedFeedBeyondTheMaximumIsRefused) {
  const auto msg = load("[envelope]\nmax_feed_mm_min = 2000.0\n[source.sim]\nprogram = \"step\"\nfeed_mm_min = 3250\n");
  EXPECT_NE(msg.find("beyond the maximum feed 2000 mm/min"), std::string::npos) << msg;
  EXPECT_NE(msg.find("max_feed_mm_min"), std::string::npos) << msg;
}

}  // namespace
