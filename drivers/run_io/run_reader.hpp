#pragma once
// Reads an eical-run/1 directory (docs/run-format.md) strictly: any problem is a
// dsp::InputError naming the file, the line and the field. Lost frames (a time step of
// k > 1 samples) are accepted and flagged (frame_flag::gap_before): nothing recorded is
// dropped, and the pipeline marks the result degraded.
#include "dsp/core/run.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

namespace eical::drivers {

class LineSource;

// The rows of samples.csv one frame at a time (what read_run() collects and a run read as
// it streams replays): strict, every problem names file, line and column.
class SampleReader {
 public:
  // Reads the header line; sets which optional channels the file has.
  SampleReader(const std::filesystem::path& file, const dsp::RunMeta& meta, dsp::ChannelPresence& channels);
  ~SampleReader();
  SampleReader(const SampleReader&) = delete;
  SampleReader& operator=(const SampleReader&) = delete;
  // The next row; false after the last (an error when there was none).
  bool next(dsp::Frame& out);
  // Whether a row so far held every field of sensor s (table 0, head 1): a sensor that
  // never does is absent (run-format.md, One sensor), its empty fields no loss.
  [[nodiscard]] bool sensor_seen(int s) const noexcept { return seen_[s]; }

 private:
  static constexpr int kColumns = 16 + 2 * dsp::kMaxPsd;
  std::unique_ptr<LineSource> src_;
  std::filesystem::path file_;
  dsp::RunMeta meta_;
  std::array<int, kColumns> where_{};
  int n_fields_ = 0, n_psd_ = 0;
  std::vector<std::string_view> fields_;
  std::int64_t prev_index_ = -1;
  std::size_t rows_ = 0;
  bool seen_[2] = {false, false};
};

// An absent sensor's empty fields flag nothing (and the frame's accel_missing only when
// the other sensor misses a field).
void absent_sensors_are_not_missing(const bool present[2], dsp::Frame& f);

// samples.csv or samples.csv.gz of a run directory (an error when neither or both).
std::filesystem::path samples_file(const std::filesystem::path& dir);

dsp::Run read_run(const std::filesystem::path& dir);

// Only run.toml (for listing and for tools that need the program before the samples).
dsp::RunMeta read_run_meta(const std::filesystem::path& run_toml);

}  // namespace eical::drivers
