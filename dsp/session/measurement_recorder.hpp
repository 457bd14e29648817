#pragma once
// The frames of one measurement, kept from `pretrigger_s` before M101 to `posttrigger_s`
// after M103, in storage allocated once. While idle a pre-trigger ring holds the last
// frames, so the recording starts with the rest the bias estimate needs even when M101
// arrives late. Single-threaded: the DSP thread owns it; finished recordings leave by
// swapping buffers (no copy, no allocation on the DSP thread) — or, with a RecordingSink,
// every frame leaves as it is recorded and nothing but the pre-trigger ring is held.
#include "dsp/core/frame.hpp"
#include "dsp/session/recording_sink.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace eical::dsp {

class MeasurementRecorder {
 public:
  // capacity_frames: longest measurement; pretrigger_frames: kept before the start. With a
  // sink the recording goes there frame by frame (capacity still bounds its length; no
  // storage is reserved for it) and leaves by take_streamed().
  MeasurementRecorder(std::size_t capacity_frames, std::size_t pretrigger_frames, RecordingSink* sink = nullptr);

  // Per sample. While idle the frame goes to the pre-trigger ring, while recording to the
  // recording (overflow is counted, never a reallocation).
  void push(const Frame& f) noexcept;
  // Starts a recording with the pre-trigger frames; the frame carrying M101 follows via push().
  void start() noexcept;
  // Stops after `posttrigger_frames` more frames (0 = now).
  void stop_after(std::size_t posttrigger_frames) noexcept;
  // Drops the current recording (abort).
  void discard() noexcept;

  [[nodiscard]] bool recording() const noexcept { return recording_; }
  [[nodiscard]] bool complete() const noexcept { return complete_; }
  [[nodiscard]] std::size_t size() const noexcept { return sink_ ? streamed_ : buffer_.size(); }
  [[nodiscard]] std::uint64_t overflow_frames() const noexcept { return overflow_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

  // Hands the complete recording over by swapping with `spare`, which must already have
  // capacity() reserved (so the recorder never allocates); returns false otherwise or when
  // no recording is complete. `spare` then holds the frames; the recorder is idle again.
  bool take(std::vector<Frame>& spare) noexcept;
  // With a sink: the complete recording (already in the sink) is handed over; the recorder is
  // idle again. False when none is complete.
  bool take_streamed() noexcept;

 private:
  // One recorded frame (within capacity: into the buffer or the sink; else counted).
  void record(const Frame& f) noexcept;

  std::size_t capacity_;
  RecordingSink* sink_ = nullptr;
  std::size_t streamed_ = 0;  // frames of this recording the sink took
  std::vector<Frame> buffer_;
  std::vector<Frame> pre_;  // ring
  std::size_t pre_head_ = 0, pre_count_ = 0;
  bool recording_ = false, complete_ = false, stopping_ = false;
  std::size_t post_left_ = 0;
  std::uint64_t overflow_ = 0;
};

}  // namespace eical::dsp
