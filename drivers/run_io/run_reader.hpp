#pragma once
// Reads an eical-run/1 directory (shared/spec/run-format.md) strictly: any problem is a
// dsp::InputError naming the file, the line and the field. Lost frames (a time step of
// k > 1 samples) are accepted and flagged (frame_flag::gap_before): nothing recorded is
// dropped, and the pipeline marks the result degraded.
#include "dsp/core/run.hpp"

#include <filesystem>

namespace eical::drivers {

dsp::Run read_run(const std::filesystem::path& dir);

// Only run.toml (for listing and for tools that need the program before the samples).
dsp::RunMeta read_run_meta(const std::filesystem::path& run_toml);

}  // namespace eical::drivers
