#pragma once
// The sensor calibration file (eical-sensor-cal/1): what an on-site identification
// (`eical identify`, ch. 8.2 without a KGM) or `eical explain` found about the two sensors
// and the DAQ, stored so that the daemon and the tools compensate with it from then on
// (eicald's [calibration] file, `eical analyze --calibration`).
//
//   format = "eical-sensor-cal/1"
//   method = "psd"            # psd (support points + set-point) | ref (reference instrument) | explain
//   run = "identify-0001"     # the run it was identified from
//   [acquisition]
//   daq_group_delay_samples = 38.93
//   daq_skew_head_samples = 0.9  # optional: the head's channels lag the table's
//   [sensors.table]           # any key of run.toml's [sensors.*]; absent keys: data sheet
//   k1_v_per_g = [...]  bias_g = [...]  f0_hz = ...  zeta = ...  to_machine = [[...], ...]
//   cross_g_per_g = [[...], [...], [...]]   # (6-4) cross-axis terms, optional
//   [sensors.head]
//   [covariance]              # the calibration's own uncertainty (eical identify writes it)
//   parameters = ["table.E_xx", ..., "head.c1_s", "daq.delay_s"]   # sensor_model_covariance.hpp
//   matrix = [[...], ...]     # symmetric, positive semi-definite; units of the parameters
//   psd_offset_sigma_um = 0.1 # a strip's own systematic error, optional
// Parameters the covariance does not list keep the data sheet's tolerance. A file without
// [covariance] is as uncertain as the data sheet (the figures' U then says so).
//
// Keys are read strictly (a typo is an error naming file, line and key).
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace eical::drivers {

struct SensorCalibration {
  std::string method = "psd";
  std::string run_id;
  std::optional<double> daq_group_delay_samples;
  std::optional<double> daq_skew_head_samples;
  dsp::SensorSpec sensors[2];                            // complete (data sheet where the file is silent)
  dsp::StaticCalibration static_cal[2];                  // cross terms (mounting is in sensors[].to_machine)
  std::optional<dsp::SensorModelCovariance> covariance;  // [covariance]
};

// Reads `file`; keys it does not set keep the values of `datasheet` (a run's or the daemon
// config's [sensors.*]). Throws InputError naming the file, line and key.
SensorCalibration read_sensor_calibration(const std::filesystem::path& file, const dsp::RunMeta& datasheet);

// Writes every key (atomically: temporary file + rename).
void write_sensor_calibration(const SensorCalibration& cal, const std::filesystem::path& file);

// The run's metadata with the calibration's sensors and delay, and the pipeline's cross
// terms: what the pipeline then compensates with.
void apply_calibration(const SensorCalibration& cal, dsp::RunMeta& meta);
void apply_calibration(const SensorCalibration& cal, dsp::PipelineConfig& config);
// The run's metadata and the analysis options (cross terms, where the model came from).
void apply_calibration(const SensorCalibration& cal, dsp::RunMeta& meta, dsp::AnalysisOptions& options);

// What an identification found, as the file stores it.
SensorCalibration calibration_from(const dsp::identify::Identification& id, const std::string& run_id);

}  // namespace eical::drivers
