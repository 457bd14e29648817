#pragma once
// Non-finite values in a frame's float channels (a broken thermistor read as NaN, a
// set-point lost on the NC link) must not reach the recording: the eical-run/1 reader
// rejects NaN, so one bad sample would make the whole run unreadable. The guard holds the
// last finite value, flags the frame (temp_missing / cmd_missing) and counts, so the
// evaluation can say what happened. Per sample: no allocation, lock or throw.
#include "dsp/core/frame.hpp"

#include <cmath>
#include <cstdint>

namespace eical::daemon {

class FrameGuard {
 public:
  FrameGuard(float temp_table_c, float temp_head_c) : last_temp_c_{temp_table_c, temp_head_c} {}

  // Returns true when `f` had a non-finite channel (now replaced).
  bool apply(dsp::Frame& f) noexcept {
    bool bad = false;
    for (int i = 0; i < 2; ++i) {
      if (std::isfinite(f.temp_c[i])) {
        last_temp_c_[i] = f.temp_c[i];
      } else {
        f.temp_c[i] = last_temp_c_[i];
        f.flags |= dsp::frame_flag::temp_missing;
        bad = true;
      }
    }
    for (int i = 0; i < 3; ++i) {
      if (std::isfinite(f.cmd_mm[i])) {
        last_cmd_mm_[i] = f.cmd_mm[i];
      } else {
        f.cmd_mm[i] = last_cmd_mm_[i];
        f.flags |= dsp::frame_flag::cmd_missing;
        bad = true;
      }
    }
    if (bad) ++bad_frames_;
    return bad;
  }
  [[nodiscard]] std::uint64_t bad_frames() const noexcept { return bad_frames_; }

 private:
  float last_temp_c_[2];
  double last_cmd_mm_[3] = {0.0, 0.0, 0.0};
  std::uint64_t bad_frames_ = 0;
};

}  // namespace eical::daemon
