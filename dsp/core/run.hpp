#pragma once
// A recorded run in memory: metadata, every frame, and which optional channels exist.
#include "dsp/core/frame.hpp"
#include "dsp/core/run_meta.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::dsp {

// Optional columns of samples.csv that this run carries.
struct ChannelPresence {
  bool ref[3] = {false, false, false};  // ref_x, ref_y, ref_z columns exist
  int psd_count = 0;                    // psd0..psd{n-1} i1/i2 columns exist
};

struct Run {
  RunMeta meta;
  ChannelPresence channels;
  std::vector<Frame> frames;
  std::optional<std::string> truth_toml;  // synthetic runs: truth.toml verbatim
  // Frames of a run read as it streams (frames stays empty; dsp/stream).
  std::size_t streamed_frames = 0;
  [[nodiscard]] std::size_t frame_count() const { return frames.empty() ? streamed_frames : frames.size(); }

  [[nodiscard]] double fs_hz() const { return meta.acquisition.fs_hz; }
  [[nodiscard]] double time_s(std::size_t i) const {
    return static_cast<double>(frames[i].sample_index) / meta.acquisition.fs_hz;
  }
};

}  // namespace eical::dsp
