// Issue 32: the text names the sensor model the pipeline compensated with — with
// --calibration the calibration, not the data sheet's — and advises identifying the
// sensors only when they were not.
#include "tools/figure_text.hpp"
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/run_files.hpp"

#include <gtest/gtest.h>

namespace eical::tools {
namespace {

dsp::Analysis psd_disagreeing(const std::string& sensor_model) {
  dsp::Analysis a;
  a.program_kind = eical::dsp::ProgramKind::circle;
  a.sensor_model = sensor_model;
  a.measurement.supports.psd_disagrees = true;
  return a;
}

TEST(SensorModelText, NamesTheCalibrationWhenOneWasApplied) {
  dsp::Run run;
  run.meta.program.kind = eical::dsp::ProgramKind::circle;
  dsp::Analysis cal = psd_disagreeing("psd");
  EXPECT_EQ(sensor_model_text(cal), "the sensor calibration (method psd)");
  plan::suggest_measurable_test(run, cal);
  ASSERT_FALSE(cal.verdict_reasons.empty());
  const std::string& r = cal.verdict_reasons.front();
  EXPECT_NE(r.find("disagree with the sensor calibration (method psd)"), std::string::npos) << r;
  EXPECT_EQ(r.find("data sheet"), std::string::npos) << r;
  EXPECT_NE(summary_text(run, cal).find("  sensor model: the sensor calibration (method psd)\n"), std::string::npos);

  dsp::Analysis sheet = psd_disagreeing("datasheet");
  EXPECT_EQ(sensor_model_text(sheet), "the data sheet's sensor model");
  plan::suggest_measurable_test(run, sheet);
  ASSERT_FALSE(sheet.verdict_reasons.empty());
  EXPECT_NE(sheet.verdict_reasons.front().find("the data sheet's sensor model: identify the sensors"),
            std::string::npos)
      << sheet.verdict_reasons.front();
}

}  // namespace
}  // namespace eical::tools
