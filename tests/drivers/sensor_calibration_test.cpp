// The sensor calibration file: round trip, data-sheet fallback, strict errors.
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace {
namespace fs = std::filesystem;
using eical::drivers::SensorCalibration;

fs::path temp_file(const std::string& name) { return fs::temp_directory_path() / ("eical_cal_" + name + "_" + std::to_string(::getpid()) + ".toml"); }

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(SensorCalibration, RoundTripKeepsEveryIdentifiedValue) {
  eical::dsp::RunMeta meta;
  SensorCalibration cal;
  cal.method = "psd";
  cal.run_id = "identify-0001";
  cal.daq_group_delay_samples = 39.125;
  for (int s = 0; s < 2; ++s) cal.sensors[s] = meta.sensors[s];
  cal.sensors[0].k1_v_per_g = {1.2391, 1.2263, 1.2307};
  cal.sensors[1].f0_hz = 943.5;
  cal.sensors[1].zeta = 0.612;
  cal.sensors[0].to_machine(0, 1) = -0.0031;
  cal.static_cal[1].cross_g_per_g(2, 0) = 0.0021;
  const fs::path p = temp_file("roundtrip");
  eical::drivers::write_sensor_calibration(cal, p);
  const SensorCalibration back = eical::drivers::read_sensor_calibration(p, meta);
  fs::remove(p);
  EXPECT_EQ(back.run_id, "identify-0001");
  ASSERT_TRUE(back.daq_group_delay_samples.has_value());
  EXPECT_DOUBLE_EQ(*back.daq_group_delay_samples, 39.125);
  EXPECT_TRUE(back.sensors[0].k1_v_per_g.isApprox(cal.sensors[0].k1_v_per_g, 0.0));
  EXPECT_DOUBLE_EQ(back.sensors[1].f0_hz, 943.5);
  EXPECT_DOUBLE_EQ(back.sensors[1].zeta, 0.612);
  EXPECT_DOUBLE_EQ(back.sensors[0].to_machine(0, 1), -0.0031);
  EXPECT_DOUBLE_EQ(back.static_cal[1].cross_g_per_g(2, 0), 0.0021);

  eical::dsp::PipelineConfig config;
  eical::drivers::apply_calibration(back, config);
  EXPECT_DOUBLE_EQ(config.acquisition.daq_group_delay_samples, 39.125);
  EXPECT_DOUBLE_EQ(config.sensors[1].zeta, 0.612);
  EXPECT_DOUBLE_EQ(config.calibration[1].cross_g_per_g(2, 0), 0.0021);
}

// What eical explain takes into the model beyond the data sheet: the head channels' DAQ
// skew and damping that grows with the acceleration.
TEST(SensorCalibration, ExplainExtensionsRoundTripAndReachThePipeline) {
  eical::dsp::RunMeta meta;
  SensorCalibration cal;
  cal.method = "explain";
  cal.run_id = "hidden-daq-0001";
  for (int s = 0; s < 2; ++s) cal.sensors[s] = meta.sensors[s];
  cal.daq_skew_head_samples = 0.75;
  cal.sensors[0].zeta_per_g = 0.9;
  const fs::path p = temp_file("explain");
  eical::drivers::write_sensor_calibration(cal, p);
  const SensorCalibration back = eical::drivers::read_sensor_calibration(p, meta);
  fs::remove(p);
  ASSERT_TRUE(back.daq_skew_head_samples.has_value());
  EXPECT_DOUBLE_EQ(*back.daq_skew_head_samples, 0.75);
  EXPECT_FALSE(back.daq_group_delay_samples.has_value());
  EXPECT_DOUBLE_EQ(back.sensors[0].zeta_per_g, 0.9);
  EXPECT_DOUBLE_EQ(back.sensors[1].zeta_per_g, 0.0);
  eical::dsp::PipelineConfig config;
  eical::drivers::apply_calibration(back, config);
  EXPECT_DOUBLE_EQ(config.acquisition.daq_skew_head_samples, 0.75);
  EXPECT_DOUBLE_EQ(config.sensors[0].zeta_per_g, 0.9);

  const fs::path bad = temp_file("badskew");
  write_text(bad, "format = \"eical-sensor-cal/1\"\n[acquisition]\ndaq_skew_head_samples = 1e9\n");
  try {
    (void)eical::drivers::read_sensor_calibration(bad, meta);
    ADD_FAILURE() << "a skew of 1e9 samples was accepted";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("daq_skew_head_samples"), std::string::npos) << e.what();
  }
  fs::remove(bad);
}

TEST(SensorCalibration, KeysAbsentFromTheFileKeepTheDataSheet) {
  eical::dsp::RunMeta meta;
  meta.sensors[1].noise_ug_per_rthz = 0.7;
  const fs::path p = temp_file("partial");
  write_text(p, "format = \"eical-sensor-cal/1\"\n[sensors.head]\nzeta = 0.55\n");
  const SensorCalibration cal = eical::drivers::read_sensor_calibration(p, meta);
  fs::remove(p);
  EXPECT_FALSE(cal.daq_group_delay_samples.has_value());
  EXPECT_DOUBLE_EQ(cal.sensors[1].zeta, 0.55);
  EXPECT_DOUBLE_EQ(cal.sensors[1].noise_ug_per_rthz, 0.7);
  EXPECT_DOUBLE_EQ(cal.sensors[0].f0_hz, meta.sensors[0].f0_hz);
}

TEST(SensorCalibration, TyposAndWrongFormatAreErrorsNamingTheKey) {
  eical::dsp::RunMeta meta;
  const fs::path p = temp_file("bad");
  auto message = [&](const std::string& text) -> std::string {
    write_text(p, text);
    try {
      (void)eical::drivers::read_sensor_calibration(p, meta);
    } catch (const eical::dsp::InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.head]\nf0_Hz = 900.0\n").find("f0_Hz"), std::string::npos);
  EXPECT_NE(message("format = \"eical-run/1\"\n").find("format"), std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.table]\nzeta = -1.0\n").find("zeta"), std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.table]\ncross_g_per_g = [[0,0],[0,0],[0,0]]\n").find("cross_g_per_g"),
            std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[acquisition]\ndaq_group_delay_samples = nan\n").find("daq_group_delay_samples"),
            std::string::npos);
  fs::remove(p);
}

}  // namespace
