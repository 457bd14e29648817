#include "daemon/service/recording_handoff.hpp"

namespace eical::daemon {

bool RecordingHandoff::hand(dsp::MeasurementSession& session, const RecordingNotes& notes,
                            const dsp::Flag* cause) noexcept {
  if (!have_token_ && returned_.try_acquire()) have_token_ = true;
  if (!have_token_ || !session.take_streamed()) return false;
  if (!cause) {
    stream_.end(notes);
  } else {
    try {
      stream_.end(notes, *cause);  // end of the data only (not real-time)
    } catch (...) {
      stream_.end(notes);  // the cause could not be kept: the recording all the same
    }
  }
  have_token_ = false;
  return true;
}

bool RecordingHandoff::offer(dsp::MeasurementSession& session, const RecordingNotes& notes) noexcept {
  return hand(session, notes, nullptr);
}

bool RecordingHandoff::offer_waiting(dsp::MeasurementSession& session, const RecordingNotes& notes,
                                     const dsp::Flag& cause) {
  if (!have_token_) returned_.acquire(), have_token_ = true;
  return hand(session, notes, &cause);
}

}  // namespace eical::daemon
