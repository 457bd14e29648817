#pragma once
// Writes an eical-run/1 directory atomically: everything goes into a temporary sibling
// directory, every file and the directory are fsynced, then it is renamed into place.
// A reader never sees half a run, and a failed write (disk full, unwritable path) never
// touches an earlier run of the same name.
#include "dsp/core/run.hpp"

#include <filesystem>

namespace eical::drivers {

struct WriteOptions {
  bool gzip = false;       // samples.csv.gz instead of samples.csv
  bool overwrite = false;  // replace an existing run (atomically) instead of failing
};

// Throws std::runtime_error naming the path and the system's reason.
void write_run(const dsp::Run& run, const std::filesystem::path& dir_in, const WriteOptions& options = {});

// run.toml text for `meta` (used by the writer; exposed for tests and `eical gen-nc`).
std::string run_toml_text(const dsp::RunMeta& meta);

// One [sensors.<name>] table with every key of run-format.md (run.toml, calibration files).
std::string sensor_section_toml(const char* name, const dsp::SensorSpec& spec);
// A small text file written atomically (temporary sibling + rename): result.json,
// calibration files. Throws std::runtime_error naming the path.
void write_text_atomic(const std::filesystem::path& file, const std::string& text);
// TOML text of a number that reads back to the same double.
std::string toml_number(double v);
// A file written and fsynced in place (inside a temporary directory that is renamed whole);
// throws std::runtime_error naming the path.
void write_synced(const std::filesystem::path& file, const std::string& text);
// fsync of a directory: its entries (a file created, a directory renamed in) are durable.
void sync_dir(const std::filesystem::path& dir);

}  // namespace eical::drivers
