#include "daemon/service/recording_stream.hpp"

#include <algorithm>

namespace eical::daemon {

namespace {
constexpr std::size_t kEvents = 64;  // a recording makes two or three; the recording thread drains them at once
}  // namespace

RecordingStream::RecordingStream(std::size_t ring_frames) : frames_(ring_frames), events_(kEvents) {}

bool RecordingStream::push_event(const RecordEvent& e) noexcept {
  const bool pushed = events_.try_push(e);
  wake_.release();
  return pushed;
}

void RecordingStream::begin() noexcept {
  lost_now_ = 0;
  RecordEvent e;
  e.kind = RecordEvent::Kind::begin, e.after_frames = pushed_;
  (void)push_event(e);
}

bool RecordingStream::frame(const dsp::Frame& f) noexcept {
  if (!frames_.try_push(f)) {
    ++lost_now_;
    lost_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  if (++pushed_ % kWakeFrames == 0) wake_.release();
  return true;
}

void RecordingStream::discard() noexcept {
  RecordEvent e;
  e.kind = RecordEvent::Kind::discard, e.after_frames = pushed_;
  (void)push_event(e);
}

void RecordingStream::end(const RecordingNotes& notes) noexcept {
  RecordEvent e;
  e.kind = RecordEvent::Kind::end, e.after_frames = pushed_, e.notes = notes, e.lost_frames = lost_now_;
  (void)push_event(e);
}

void RecordingStream::end(const RecordingNotes& notes, const dsp::Flag& cause) {
  {
    std::lock_guard lk(cause_mu_);
    cause_ = cause;
  }
  RecordEvent e;
  e.kind = RecordEvent::Kind::end, e.after_frames = pushed_, e.notes = notes, e.lost_frames = lost_now_;
  e.has_cause = true;
  (void)push_event(e);
}

void RecordingStream::wait(std::chrono::milliseconds timeout) { (void)wake_.try_acquire_for(timeout); }

std::size_t RecordingStream::drain(std::span<dsp::Frame> out, RecordEvent& event, bool& has_event) noexcept {
  has_event = false;
  // The frames there now first, the events after: an event pushed before any of these frames
  // is then seen (the DSP thread pushes in order), so none of its later frames slips ahead of it.
  const std::size_t available = frames_.size_approx();
  if (!next_event_) {
    RecordEvent e;
    if (events_.try_pop(e)) next_event_ = e;
  }
  std::size_t limit = std::min(out.size(), available);
  if (next_event_) {
    if (drained_ >= next_event_->after_frames) {  // its frames are out: the event now
      event = *next_event_;
      next_event_.reset();
      has_event = true;
      return 0;
    }
    limit = std::min<std::size_t>(limit, next_event_->after_frames - drained_);
  }
  const std::size_t n = frames_.pop_many(out.first(limit));
  drained_ += n;
  return n;
}

dsp::Flag RecordingStream::take_cause() {
  std::lock_guard lk(cause_mu_);
  return std::move(cause_);
}

}  // namespace eical::daemon
