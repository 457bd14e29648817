#pragma once
// The recording directory as the fault cases inspect it: the completed runs (visible
// directories), the temporaries a write leaves while it runs (hidden entries, *.tmp), and
// a byte-for-byte snapshot to prove that earlier runs survived a fault intact.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace eical::faults {

namespace fs = std::filesystem;

// A fresh directory under the system's temporary directory, removed with the object.
struct Scratch {
  explicit Scratch(const std::string& tag);
  ~Scratch();
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  fs::path dir;
};

// Run directories (names not starting with '.'), sorted by name.
std::vector<fs::path> completed_runs(const fs::path& recording_dir);
// Hidden entries of the recording directory (write temporaries, probes; not eicald's state
// file) and *.tmp files inside run directories.
std::vector<fs::path> temporaries(const fs::path& recording_dir);

// Every file of every run: run name/file → bytes.
using Snapshot = std::map<std::string, std::string>;
Snapshot snapshot(const fs::path& recording_dir);
// How many runs of `before` are still there with identical bytes and read back whole
// (drivers::read_run; result.json parses).
std::size_t intact_runs(const Snapshot& before, const fs::path& recording_dir);
std::size_t runs_in(const Snapshot& s);
// A run directory reads back (samples and run.toml) and has a result.json that parses.
bool readable_with_result(const fs::path& run, std::string* why = nullptr);

std::string slurp(const fs::path& file);

}  // namespace eical::faults
