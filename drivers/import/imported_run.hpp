#pragma once
// An eical-run/1 from a recording made by another system: one sensor (the other triplex
// empty: run-format.md "One sensor"), its samples on the uniform clock, the set-point of
// the motion at every frame, M101 at the first sample and M103 at the last, program kind
// "freeform". Counts: 1 count = 1 µg (k1 = 1 V/g, adc_lsb_volt = 1 µV, 32-bit), so the
// resampled values lose nothing to rounding; no DAQ delay (a MEMS chip samples its own
// low-pass output). No temperature is recorded: the temperature fields are empty.
// import.toml beside run.toml says how it was imported (clock, jitter, lost frames, the
// time offset with its uncertainty).
#include "drivers/import/mounting_check.hpp"
#include "drivers/import/time_offset.hpp"
#include "drivers/import/uniform_clock.hpp"
#include "dsp/core/run.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace eical::drivers {

inline constexpr double kImportCountsPerG = 1e6;

struct ImportSetup {
  std::string id;
  int part = 1;                                              // dsp::Sensor of the recording: 0 table, 1 head
  std::string chip = "adxl345";                              // sim/sensor/mems_chip: noise and corner of its data sheet
  double bandwidth_hz = 0.0;                                 // > 0: overrides the chip's corner at the capture's rate
  double noise_ug_per_rthz = -1.0;                           // >= 0: overrides the chip's noise (two-sided)
  Eigen::Matrix3d to_machine = Eigen::Matrix3d::Identity();  // the stated mounting
  dsp::MachineLayout machine;
  dsp::Site site;
  double feed_mm_min = 1.0;  // the motion's peak speed
  double accel_scale = 1.0;  // multiplies the recorded acceleration (a recorder's wrong constants)
};

// The sensor's data sheet for run.toml at the capture's rate.
dsp::SensorSpec import_sensor_spec(const ImportSetup& setup, double fs_hz);

// The set-point on its own clock and where it is known; outside [t_begin, t_end] the
// frames are flagged cmd_missing (unless `hold_outside`: the machine rested there).
struct ImportSetPoint {
  std::function<Eigen::Vector3d(double t_s)> position_mm;
  double t_begin_s = 0.0, t_end_s = 0.0;
  bool hold_outside = false;
};

// offset_s = recorder time − set-point time (estimate_offset).
dsp::Run imported_run(const UniformClock& clock, const UniformSeries& accel_g, const ImportSetup& setup,
                      const ImportSetPoint& set_point, double offset_s);

// What import.toml records.
struct ImportReport {
  std::string kind;  // "klipper" | "shaketune" | "csv"
  std::string source, nc_source;
  std::string excitation;  // how the set-point was made
  UniformClock accel_clock;
  std::optional<UniformClock> nc_clock;
  std::size_t samples = 0;
  OffsetEstimate offset;
  double accel_scale = 1.0;               // applied to the recording (ImportSetup::accel_scale)
  std::optional<MountingCheck> mounting;  // gravity and motion against the stated scale and axes
};
std::string import_report_toml(const ImportReport& report);
void write_import_report(const std::filesystem::path& run_dir, const ImportReport& report);

// Throws InputError naming `source` when the offset's peak is not told from noise or the
// commanded acceleration explains less than kMinExplained of the measured variance: the
// recording does not hold the motion the set-point describes (wrong test parameters, axis
// or file; a sensor on a part that does not move).
inline constexpr double kMinExplained = 0.05;
void require_alignment(const OffsetEstimate& offset, const std::string& source);

// "xy" → {"x", "y"}; throws InputError naming `what` for other letters.
std::vector<std::string> axis_list(const std::string& letters, const std::string& what);

}  // namespace eical::drivers
