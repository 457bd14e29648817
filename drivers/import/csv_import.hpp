#pragma once
// `eical import csv`: a generic accelerometer CSV plus an NC trace of the commanded
// position (a LinuxCNC halsampler file, or a servo-trace CSV export) into eical-run/1.
// Both are put on uniform clocks (drivers/import/uniform_clock; the NC trace's lost
// samples bridged by the same interpolation: a set-point is smooth), the NC positions made
// continuous by a natural cubic spline (sim/nc SampledSetPoint), and the offset between
// the two clocks estimated by cross-correlating the spline's second derivative with the
// measured acceleration. Frames outside the NC trace are flagged cmd_missing.
#include "drivers/import/capture_files.hpp"
#include "drivers/import/klipper_import.hpp"

#include <filesystem>

namespace eical::drivers {

struct CsvImport {
  CsvColumns accel_columns;
  AccelUnit unit = AccelUnit::mps2;
  bool nc_halsampler = true;
  double servo_period_s = 0.001;  // halsampler: [EMCMOT]SERVO_PERIOD
  CsvColumns nc_columns;
  ImportSetup setup;
};

ImportResult import_csv(const std::filesystem::path& accel_file, const std::filesystem::path& nc_file,
                        const CsvImport& options);

}  // namespace eical::drivers
