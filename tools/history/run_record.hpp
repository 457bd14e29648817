#pragma once
// A recorded run directory as a history record (`eical history add RUN`): its result.json
// when it has one, otherwise the run is analysed as `eical analyze` would (with
// `calibration` when given: then always analysed, the stored result says which
// calibration). Machine and time come from run.toml (machine overridable), the run path is
// made absolute.
#include "history/record/record.hpp"

#include <filesystem>
#include <string>

namespace eical::tools {

struct AddOptions {
  std::string machine;                // "": run.toml's [machine] name
  std::filesystem::path calibration;  // eical-sensor-cal/1, or empty
};

// Throws naming the run and the cause (no run.toml, malformed result.json, ...).
history::Record run_record(const std::filesystem::path& run_dir, const AddOptions& options);

}  // namespace eical::tools
