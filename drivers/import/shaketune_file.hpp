#pragma once
// Shake&Tune's measurements file (.stdata, Klipper plugin K-ShakeTune): a zstd stream of JSON
// lines, one measurement each, {"name": "...", "samples": [[t, ax, ay, az], ...]}: Klipper's
// accelerometer samples as the plugin received them (print-time seconds and mm/s², through
// the printer's axes_map), the same values a raw_data CSV holds. Its legacy outputs are
// Klipper's raw CSVs (read_klipper_capture). The plugin's first .stdata releases pickled the
// list instead: those are refused by name, since unpickling runs whatever the file says.
// Every problem is an InputError naming the file and, where there is one, the line.
#include "drivers/import/capture_files.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace eical::drivers {

struct ShakeTuneMeasurement {
  std::string name;
  StampedAccel capture;  // source "file#name"
};

std::vector<ShakeTuneMeasurement> read_shaketune_stdata(const std::filesystem::path& file);
void write_shaketune_stdata(const std::filesystem::path& file, const std::vector<ShakeTuneMeasurement>& measurements);

// The measurement to import: the one named, or the only one when `name` is empty. Refused
// otherwise, listing the names the file holds and their lengths.
const ShakeTuneMeasurement& pick_measurement(const std::vector<ShakeTuneMeasurement>& measurements,
                                             const std::string& name, const std::string& source);

}  // namespace eical::drivers
