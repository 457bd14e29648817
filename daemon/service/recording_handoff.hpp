#pragma once
// A finished measurement leaves the DSP thread for the evaluation thread. Its frames are
// already on their way to disk (RecordingStream: the recording thread writes them as they
// are measured), so the hand-over is the recording's end with its notes — and a token: the
// DSP thread hands the next recording over only when the evaluation thread has finished
// the previous one (written it, analysed it), as when the recording itself changed hands.
// A recording the disk cannot take thus waits alone, and M-codes are refused meanwhile
// (the session stays EVALUATING, counted as deferred hand-overs). The token comes back
// through a semaphore (futex-based, lock-free on its fast path): neither side polls.
#include "daemon/service/recording_notes.hpp"
#include "daemon/service/recording_stream.hpp"
#include "dsp/session/measurement_session.hpp"

#include <atomic>
#include <semaphore>
#include <string>

namespace eical::daemon {

class RecordingHandoff {
 public:
  explicit RecordingHandoff(RecordingStream& stream) : stream_(stream) {}

  // DSP thread, per frame: hands the session's complete recording over when the evaluation
  // of the previous one is done; false (nothing waits) otherwise.
  bool offer(dsp::MeasurementSession& session, const RecordingNotes& notes) noexcept;
  // DSP thread at the end of the data (not real-time): waits for the previous evaluation.
  bool offer_waiting(dsp::MeasurementSession& session, const RecordingNotes& notes, const dsp::Flag& cause);

  // Evaluation thread: the recording handed over last is evaluated.
  void done() { returned_.release(); }
  void quit() { quit_.store(true); }
  // Any thread: quit() was called (the evaluator stops retrying a failed write).
  [[nodiscard]] bool quitting() const noexcept { return quit_.load(); }

 private:
  bool hand(dsp::MeasurementSession& session, const RecordingNotes& notes, const dsp::Flag* cause) noexcept;

  RecordingStream& stream_;
  bool have_token_ = true;  // DSP thread
  std::binary_semaphore returned_{0};
  std::atomic<bool> quit_{false};
};

}  // namespace eical::daemon
