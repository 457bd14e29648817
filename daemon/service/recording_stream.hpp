#pragma once
// The DSP thread's side of the recording: each recorded frame goes into a lock-free ring
// that the recording thread (RecordingWriter) drains and writes to disk as it is measured,
// and a recording's start, end (with what the DSP thread knows about it) and discard go
// into a second ring, in order with the frames. Nothing of a measurement stays in memory
// but the ring: its length costs disk, not RAM. The DSP thread never allocates, locks or
// waits here; it wakes the recording thread (a semaphore) every kWakeFrames frames and at
// each event. A frame the ring has no room for (the recording thread stalled for the
// ring's length) is lost, counted and flagged in its recording's result.
#include "daemon/service/recording_notes.hpp"
#include "drivers/ring/spsc_ring.hpp"
#include "dsp/core/flag.hpp"
#include "dsp/session/recording_sink.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <semaphore>
#include <span>
#include <string>

namespace eical::daemon {

struct RecordEvent {
  enum class Kind : std::uint8_t { begin, end, discard };
  Kind kind = Kind::begin;
  std::uint64_t after_frames = 0;  // frames pushed before it (its place among them)
  RecordingNotes notes;            // end: what the DSP thread knows about the recording
  std::uint64_t lost_frames = 0;   // end: frames of the recording the ring had no room for
  bool has_cause = false;          // end: take_cause() says why it ended without M103
};

class RecordingStream final : public dsp::RecordingSink {
 public:
  static constexpr std::uint64_t kWakeFrames = 1024;  // 0.1 s at 10 kHz

  explicit RecordingStream(std::size_t ring_frames);

  // DSP thread (dsp::RecordingSink).
  void begin() noexcept override;
  [[nodiscard]] bool frame(const dsp::Frame& f) noexcept override;
  void discard() noexcept override;
  // DSP thread: the recording begun last is complete.
  void end(const RecordingNotes& notes) noexcept;
  // DSP thread at the end of the data (not real-time): complete, with why it ended.
  void end(const RecordingNotes& notes, const dsp::Flag& cause);

  // Recording thread: waits until woken or `timeout` passed.
  void wait(std::chrono::milliseconds timeout);
  // Recording thread: up to out.size() frames and whether an event is due before them
  // (`event` filled, popped): the frames first, then the event.
  std::size_t drain(std::span<dsp::Frame> out, RecordEvent& event, bool& has_event) noexcept;
  // Recording thread: the cause of the end event just drained (has_cause).
  dsp::Flag take_cause();
  // Recording thread: wakes wait() (to stop).
  void wake() noexcept { wake_.release(); }

  [[nodiscard]] std::uint64_t lost_frames() const noexcept { return lost_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::size_t capacity() const noexcept { return frames_.capacity(); }
  [[nodiscard]] std::size_t queued() const noexcept { return frames_.size_approx(); }  // any thread, approximate

 private:
  bool push_event(const RecordEvent& e) noexcept;

  drivers::SpscRing<dsp::Frame> frames_;
  drivers::SpscRing<RecordEvent> events_;
  std::counting_semaphore<1 << 30> wake_{0};
  std::uint64_t pushed_ = 0;    // DSP thread: frames into the ring
  std::uint64_t lost_now_ = 0;  // DSP thread: frames of this recording lost
  std::atomic<std::uint64_t> lost_{0};
  std::uint64_t drained_ = 0;              // recording thread: frames out of the ring
  std::optional<RecordEvent> next_event_;  // recording thread: popped, its frames not yet all out
  std::mutex cause_mu_;
  dsp::Flag cause_{dsp::FlagCode::source_stopped, {}, {}};
};

}  // namespace eical::daemon
