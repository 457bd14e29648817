#pragma once
// A finished measurement leaves the DSP thread for the evaluation thread by swapping
// buffers, without a lock: the DSP thread holds one spare buffer (capacity reserved at
// start) and swaps it with the session's recording; the evaluation thread returns the
// storage when it is done. Semaphores (futex-based, lock-free on their fast path) carry
// the hand-over and the return, so neither side polls. While the evaluator still holds the
// previous recording the DSP thread keeps the new one in the session (counted) and offers
// it again on the next frame.
#include "dsp/core/frame.hpp"
#include "dsp/session/measurement_session.hpp"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <semaphore>
#include <string>
#include <vector>

namespace eical::daemon {

// What the DSP thread knows about a recording that the frames do not say.
struct RecordingNotes {
  std::uint64_t nonfinite_frames = 0;  // frames whose NaN/Inf channels the guard replaced
  double program_p = std::nan("");     // M101's P word (program number); NaN = none given
  std::int64_t index_offset = 0;       // added to the source's sample indices (after reopens)
  double source_rate_ratio = 0.0;      // the source's delivered rate / fs_hz while off (0: never off)
};

struct RecordingJob {
  std::vector<dsp::Frame> frames;
  RecordingNotes notes;
  std::string cause;  // empty, or why it ended without M103 (a quality flag)
};

class RecordingHandoff {
 public:
  explicit RecordingHandoff(std::size_t capacity_frames) : capacity_(capacity_frames) {
    spare_.reserve(capacity_frames);
  }

  // DSP thread, per frame: hands the session's complete recording over when the spare
  // buffer is back; false (nothing waits) otherwise.
  bool offer(dsp::MeasurementSession& session, const RecordingNotes& notes) noexcept;
  // DSP thread at the end of the data (not real-time): waits for the spare buffer.
  bool offer_waiting(dsp::MeasurementSession& session, const RecordingNotes& notes, const std::string& cause);

  // Evaluation thread: the next recording; false when quit() was called and none is left.
  bool wait_job(RecordingJob& job);
  // Evaluation thread: the storage of the job it finished (its capacity is kept).
  void give_back(std::vector<dsp::Frame>&& storage);
  void quit();
  // Any thread: quit() was called (the evaluator stops retrying a failed write).
  [[nodiscard]] bool quitting() const noexcept { return quit_.load(); }

 private:
  bool hand(dsp::MeasurementSession& session, const RecordingNotes& notes, const std::string* cause) noexcept;

  std::size_t capacity_;
  std::vector<dsp::Frame> spare_;  // DSP thread
  bool have_spare_ = true;         // DSP thread
  RecordingJob slot_;              // DSP thread writes it while it has the spare; evaluator reads after job_ready_
  std::counting_semaphore<2> job_ready_{0};  // a job, then quit()
  std::vector<dsp::Frame> returned_;         // evaluator writes, DSP reads after returned_ready_
  std::binary_semaphore returned_ready_{0};
  std::atomic<bool> quit_{false};
};

}  // namespace eical::daemon
