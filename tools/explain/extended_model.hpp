#pragma once
// The accepted extensions made part of eical's model: the significant sensor effects as a
// sensor calibration (eical-sensor-cal/1, method "explain": what eical analyze
// --calibration and eicald's [calibration] then compensate with), the machine effects and
// the calibrated sensors as a scenario (eical-scenario/1) with which `eical simulate`
// reproduces the run.
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/core/run.hpp"
#include "dsp/model/explain.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace eical::tools::explain {

struct ExtendedModel {
  drivers::SensorCalibration calibration;
  std::string scenario_toml;
  std::vector<std::string> notes;  // what was taken over, and what the pipeline cannot compensate (yet)
};

ExtendedModel extended_model(const dsp::Run& run, const dsp::model::RunExplanation& explanation);
void write_extended_model(const ExtendedModel& model, const std::filesystem::path& calibration_file,
                          const std::filesystem::path& scenario_file);

}  // namespace eical::tools::explain
