#pragma once
// Frames that can be read more than once, in order: what the streamed analysis reads
// (twice) instead of holding the run. A recorded run on disk reads its file again
// (drivers/run_io/run_stream.hpp); frames already in memory (eicald's recording) are
// replayed from there.
#include "dsp/core/frame.hpp"

#include <cstddef>
#include <functional>
#include <vector>

namespace eical::dsp {

class FrameReplay {
 public:
  virtual ~FrameReplay() = default;
  // Every frame of the run, in order. Throws InputError on bad input (naming the cause).
  virtual void replay(const std::function<void(const Frame&)>& frame) = 0;
  // About how many frames (what to reserve for); 0 when unknown.
  [[nodiscard]] virtual std::size_t size_hint() const { return 0; }
};

class StoredFrames final : public FrameReplay {
 public:
  explicit StoredFrames(const std::vector<Frame>& frames) : frames_(frames) {}
  void replay(const std::function<void(const Frame&)>& frame) override {
    for (const Frame& f : frames_) frame(f);
  }
  [[nodiscard]] std::size_t size_hint() const override { return frames_.size(); }

 private:
  const std::vector<Frame>& frames_;
};

}  // namespace eical::dsp
