#pragma once
// Where a recording's frames go as they are recorded, instead of a buffer holding the whole
// measurement: eicald hands each one to a thread of its own that writes the run to disk as
// it is measured (daemon/service/recording_stream.hpp), so that a measurement of any length
// costs no more memory than a ring of a few seconds. Called on the DSP thread, per frame:
// an implementation must not allocate, lock, block or throw.
#include "dsp/core/frame.hpp"

namespace eical::dsp {

class RecordingSink {
 public:
  virtual ~RecordingSink() = default;
  // A recording starts: its frames follow (the pre-trigger frames first).
  virtual void begin() noexcept = 0;
  // A frame of it; false when there was no room for it (it is lost: the caller counts it).
  [[nodiscard]] virtual bool frame(const Frame& f) noexcept = 0;
  // The recording begun last is dropped (the measurement was aborted).
  virtual void discard() noexcept = 0;
};

}  // namespace eical::dsp
