// The sensor calibration file: round trip, data-sheet fallback, strict errors.
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>

namespace {
namespace fs = std::filesystem;
using eical::drivers::SensorCalibration;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("eical_cal_" + name + "_" + std::to_string(::getpid()) + ".toml");
}

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
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.head]\nf0_Hz = 900.0\n").find("f0_Hz"),
            std::string::npos);
  EXPECT_NE(message("format = \"eical-run/1\"\n").find("format"), std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.table]\nzeta = -1.0\n").find("zeta"), std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[sensors.table]\ncross_g_per_g = [[0,0],[0,0],[0,0]]\n")
                .find("cross_g_per_g"),
            std::string::npos);
  EXPECT_NE(message("format = \"eical-sensor-cal/1\"\n[acquisition]\ndaq_group_delay_samples = nan\n")
                .find("daq_group_delay_samples"),
            std::string::npos);
  fs::remove(p);
}

}  // namespace

namespace {

// The calibration's covariance: written, read back exactly, applied to the analysis; a
// file without one is as uncertain as the data sheet.
TEST(SensorCalibration, CovarianceRoundTripsAndIsApplied) {
  namespace u = eical::dsp;
  eical::dsp::RunMeta meta;
  SensorCalibration cal;
  for (int s = 0; s < 2; ++s) cal.sensors[s] = meta.sensors[s];
  cal.covariance = u::datasheet_covariance(meta.sensors, meta.acquisition.fs_hz);
  auto& c = cal.covariance->covariance;
  const int xx = u::error_index(0, 0, 0), xy = u::error_index(0, 0, 1);
  c(xx, xx) = 2.0e-10, c(xy, xy) = 3.0e-10, c(xx, xy) = c(xy, xx) = 1.0e-10;
  c(u::kDelayIndex, u::kDelayIndex) = 4e-12;
  cal.covariance->psd_offset_sigma_um = 0.2;
  const fs::path p = temp_file("covariance");
  eical::drivers::write_sensor_calibration(cal, p);
  const SensorCalibration back = eical::drivers::read_sensor_calibration(p, meta);
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_LT((back.covariance->covariance - c).cwiseAbs().maxCoeff(), 1e-24);
  EXPECT_DOUBLE_EQ(back.covariance->psd_offset_sigma_um, 0.2);
  eical::dsp::AnalysisOptions opt;
  eical::drivers::apply_calibration(back, meta, opt);
  ASSERT_TRUE(opt.model_covariance.has_value());
  EXPECT_DOUBLE_EQ(opt.model_covariance->covariance(xx, xy), 1.0e-10);
  fs::remove(p);

  SensorCalibration plain = cal;
  plain.covariance.reset();
  eical::drivers::write_sensor_calibration(plain, p);
  eical::dsp::AnalysisOptions opt2;
  eical::drivers::apply_calibration(eical::drivers::read_sensor_calibration(p, meta), meta, opt2);
  ASSERT_TRUE(opt2.model_covariance.has_value());
  EXPECT_DOUBLE_EQ(opt2.model_covariance->covariance(xx, xx),
                   u::datasheet_covariance(meta.sensors, meta.acquisition.fs_hz).covariance(xx, xx));
  EXPECT_NE(opt2.model_covariance->source.find("data sheet"), std::string::npos);
  fs::remove(p);
}

TEST(SensorCalibration, CovarianceIsReadStrictly) {
  eical::dsp::RunMeta meta;
  const std::string head = "format = \"eical-sensor-cal/1\"\nmethod = \"psd\"\n[covariance]\n";
  struct Case {
    std::string body, cause;
  };
  for (const auto& c :
       {Case{"parameters = [\"table.E_xq\"]\nmatrix = [[1e-10]]\n", "unknown parameter 'table.E_xq'"},
        Case{"parameters = [\"table.E_xx\", \"table.E_xy\"]\nmatrix = [[1e-10, 2e-11], [0.0, 1e-10]]\n",
             "not symmetric"},
        Case{"parameters = [\"table.E_xx\", \"table.E_xy\"]\nmatrix = [[1e-10, 2e-10], [2e-10, 1e-10]]\n",
             "positive semi-definite"},
        Case{"parameters = [\"table.E_xx\", \"table.E_xx\"]\nmatrix = [[1e-10, 0.0], [0.0, 1e-10]]\n", "listed twice"},
        Case{"parameters = [\"table.E_xx\"]\nmatrix = [[1e-10]]\npsd_offset = 0.1\n", "psd_offset"}}) {
    const fs::path p = temp_file("strict");
    write_text(p, head + c.body);
    try {
      (void)eical::drivers::read_sensor_calibration(p, meta);
      ADD_FAILURE() << "accepted: " << c.body;
    } catch (const eical::dsp::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.cause), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("covariance"), std::string::npos) << e.what();
    }
    fs::remove(p);
  }
}

}  // namespace
