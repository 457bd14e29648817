#pragma once
// `eical import klipper`: a Klipper raw accelerometer capture of a resonance test into
// eical-run/1. The set-point is Klipper's own excitation (sim/nc/klipper_excitation),
// whose start in the capture is unknown: it is found by cross-correlating the commanded
// acceleration with the measured one (drivers/import/time_offset) and reported. Before the
// test and after it the head rests where the test starts and ends (Klipper dwells before
// the test and stops the capture once the moves are done).
#include "drivers/import/capture_files.hpp"
#include "drivers/import/imported_run.hpp"
#include "sim/nc/klipper_excitation.hpp"

#include <filesystem>
#include <string>

namespace eical::drivers {

struct KlipperImport {
  sim::nc::KlipperTest test = sim::nc::KlipperTest::current();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // Klipper's AXIS
  Eigen::Vector3d start_mm = Eigen::Vector3d::Zero();
  ImportSetup setup;  // sensor spec (chip, mounting), part, layout, id
};

struct ImportResult {
  dsp::Run run;
  ImportReport report;
};

ImportResult import_klipper(const std::filesystem::path& file, const KlipperImport& options);

// A measurement of Shake&Tune's .stdata (drivers/import/shaketune_file): the same samples a
// raw_data CSV holds, from the same excitation (the plugin drives Klipper's own generator).
// `measurement` empty: the file's only one.
ImportResult import_shaketune(const std::filesystem::path& file, const std::string& measurement,
                              const KlipperImport& options);

// What both do once the samples are read.
ImportResult import_klipper_capture(const StampedAccel& capture, const KlipperImport& options);

}  // namespace eical::drivers
