#include "daemon/service/recording_handoff.hpp"

namespace eical::daemon {

bool RecordingHandoff::hand(dsp::MeasurementSession& session, const RecordingNotes& notes,
                            const std::string* cause) noexcept {
  if (!have_spare_ && returned_ready_.try_acquire()) spare_.swap(returned_), have_spare_ = true;
  if (!have_spare_ || !session.take(spare_)) return false;
  // The evaluator took the previous slot before it returned the spare: the slot is free.
  slot_.frames.swap(spare_);
  slot_.notes = notes;
  if (cause)
    slot_.cause = *cause;  // end of the data only (not real-time)
  else
    slot_.cause.clear();  // keeps the capacity: no allocation
  have_spare_ = false;
  job_ready_.release();
  return true;
}

bool RecordingHandoff::offer(dsp::MeasurementSession& session, const RecordingNotes& notes) noexcept {
  return hand(session, notes, nullptr);
}

bool RecordingHandoff::offer_waiting(dsp::MeasurementSession& session, const RecordingNotes& notes,
                                     const std::string& cause) {
  if (!have_spare_) returned_ready_.acquire(), spare_.swap(returned_), have_spare_ = true;
  return hand(session, notes, &cause);
}

bool RecordingHandoff::wait_job(RecordingJob& job) {
  job_ready_.acquire();
  if (slot_.frames.empty() && quit_.load()) return false;
  job.frames.swap(slot_.frames);
  job.notes = slot_.notes;
  job.cause = slot_.cause;
  slot_.frames.clear();
  return true;
}

void RecordingHandoff::give_back(std::vector<dsp::Frame>&& storage) {
  storage.clear();
  if (storage.capacity() < capacity_) storage.reserve(capacity_);
  returned_ = std::move(storage);
  returned_ready_.release();
}

void RecordingHandoff::quit() {
  quit_.store(true);
  job_ready_.release();
}

}  // namespace eical::daemon
