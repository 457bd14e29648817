#pragma once
// The calibration programs an NC may run, by number: M101's P word names one, and eicald
// reconstructs its set-point with eical's interpolator. Each program is the [program]
// table that `eical gen-nc ... --meta FILE` writes (kind, geometry and the G-code), stored
// as <directory>/<number>.toml.
#include "dsp/core/run_meta.hpp"

#include <filesystem>
#include <string>

namespace eical::drivers {

// Reads the [program] table of `file` (with its gcode); InputError naming file and line.
dsp::Program read_program_file(const std::filesystem::path& path);

class ProgramCatalog {
 public:
  explicit ProgramCatalog(std::filesystem::path directory) : dir_(std::move(directory)) {}
  // <directory>/<number>.toml; InputError when it is missing or not a program.
  [[nodiscard]] dsp::Program program(int number) const;
  [[nodiscard]] std::filesystem::path file_of(int number) const { return dir_ / (std::to_string(number) + ".toml"); }
  [[nodiscard]] const std::filesystem::path& directory() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

}  // namespace eical::drivers
