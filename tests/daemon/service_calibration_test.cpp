// eicald with an identified calibration ([calibration] file): the live path, the recording
// and its evaluation all use it (run.toml carries the calibrated sensors, result.json says
// where the model came from, and the PSD strips of the configuration are recorded); a
// calibration file that cannot be read stops the start with its name.
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/service.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "sim/scenario.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

eical::daemon::DaemonConfig base(const fs::path& dir) {
  eical::daemon::DaemonConfig c;
  c.source.kind = "sim";
  c.source.pacing = "free_running";
  c.source.sim_repeats = 2;
  c.source.sim_repeat_program = false;
  c.triggers.inputs = {"frame"};
  c.recording.dir = dir / "runs";
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 30.0;
  c.psd = eical::sim::psd_config_b(10.0);
  return c;
}

TEST(ServiceCalibration, RecordingsAndResultsUseTheIdentifiedCalibration) {
  const fs::path dir = fs::temp_directory_path() / ("eicald-cal-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  eical::daemon::DaemonConfig c = base(dir);
  eical::drivers::SensorCalibration cal;
  cal.method = "psd";
  cal.run_id = "identify-test";
  cal.sensors[0] = c.sensors[0], cal.sensors[1] = c.sensors[1];
  cal.sensors[0].zeta = 0.65;  // what an identification could have found
  cal.sensors[0].k1_v_per_g[0] *= 1.0002;
  eical::drivers::write_sensor_calibration(cal, dir / "cal.toml");
  c.calibration_file = dir / "cal.toml";
  std::atomic<bool> stop{false};
  eical::daemon::Service(c).run(stop, [](const eical::daemon::ServiceStatus&) {});
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(dir / "runs")) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 1u);
  const auto run = eical::drivers::read_run(runs[0]);
  EXPECT_DOUBLE_EQ(run.meta.sensors[0].zeta, 0.65);
  EXPECT_DOUBLE_EQ(run.meta.sensors[0].k1_v_per_g[0], cal.sensors[0].k1_v_per_g[0]);
  EXPECT_EQ(run.channels.psd_count, 2);  // the strips' readings are recorded
  std::ifstream is(runs[0] / "result.json");
  const auto j = nlohmann::json::parse(is);
  EXPECT_EQ(j["sensor_model"]["identified"], true);
  EXPECT_EQ(j["sensor_model"]["source"], "psd");
  fs::remove_all(dir);
}

TEST(ServiceCalibration, AnUnreadableCalibrationStopsTheStartNamingIt) {
  const fs::path dir = fs::temp_directory_path() / ("eicald-cal-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  eical::daemon::DaemonConfig c = base(dir);
  std::ofstream(dir / "cal.toml") << "format = \"eical-sensor-cal/1\"\n[sensors.table]\nzeta = \"high\"\n";
  c.calibration_file = dir / "cal.toml";
  std::atomic<bool> stop{false};
  try {
    eical::daemon::Service(c).run(stop, [](const eical::daemon::ServiceStatus&) {});
    FAIL() << "started with a broken calibration";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cal.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zeta"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
