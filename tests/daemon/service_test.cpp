// eicald's service loop with the simulated backend, free-running: one measurement is
// recorded, written atomically with its result, and the result equals a fresh analysis
// of the recorded run (what `eical analyze` prints).
#include "daemon/service/service.hpp"
#include "daemon/config/daemon_config.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

TEST(Service, SimulatedProgramIsRecordedAndEvaluated) {
  const fs::path dir = fs::temp_directory_path() / ("eicald-" + std::to_string(std::random_device{}()));
  eical::daemon::DaemonConfig c;
  c.source.kind = "sim";
  c.source.pacing = "free_running";
  c.source.sim_repeats = 2;
  c.source.sim_repeat_program = false;
  c.recording.dir = dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 30.0;
  std::atomic<bool> stop{false};
  int status_calls = 0;
  eical::daemon::Service(c).run(stop, [&](const eical::daemon::ServiceStatus&) { ++status_calls; });
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(dir)) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 1u);
  ASSERT_TRUE(fs::exists(runs[0] / "result.json"));
  std::ifstream is(runs[0] / "result.json");
  const auto j = nlohmann::json::parse(is);
  const auto run = eical::drivers::read_run(runs[0]);
  const auto a = eical::dsp::analyze_run(run);
  ASSERT_TRUE(a.circle);
  EXPECT_EQ(j["format"], "eical-result/1");
  EXPECT_EQ(j["circle"]["revolutions"], 2);
  EXPECT_NEAR(j["circle"]["circular_deviation_G_um"].get<double>(), a.circle->circular_deviation_G_um, 1e-9);
  EXPECT_NEAR(j["circle"]["radius_mean_deviation_um"].get<double>(), a.circle->radius_mean_deviation_um, 1e-9);
  fs::remove_all(dir);
}

TEST(Service, AbsentHardwareIsAClearErrorAtStart) {
  eical::daemon::DaemonConfig c;
  c.source.kind = "usb_daq";
  std::atomic<bool> stop{false};
  try {
    eical::daemon::Service(c).run(stop, [](const eical::daemon::ServiceStatus&) {});
    FAIL() << "started without a DAQ";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("usb_daq"), std::string::npos) << e.what();
  }
}

}  // namespace
