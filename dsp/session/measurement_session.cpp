#include "dsp/session/measurement_session.hpp"

#include <cmath>

namespace eical::dsp {
namespace {

std::size_t frames_of(double seconds, double fs_hz) {
  return static_cast<std::size_t>(std::llround(std::max(0.0, seconds) * fs_hz));
}

}  // namespace

MeasurementSession::MeasurementSession(const SessionConfig& config, RecordingSink* sink)
    : config_(config),
      recorder_(frames_of(config.max_measurement_s, config.fs_hz), frames_of(config.pretrigger_s, config.fs_hz), sink),
      posttrigger_frames_(frames_of(config.posttrigger_s, config.fs_hz)) {}

bool MeasurementSession::queue_trigger(std::int64_t sample_index, int code) noexcept {
  if (pending_count_ == pending_.size()) {
    ++counters_.trigger_queue_full;
    return false;
  }
  pending_[pending_count_++] = {sample_index, code};
  return true;
}

void MeasurementSession::apply_trigger(int code) noexcept {
  Event e;
  switch (code) {
    case trigger::program_start: e = Event::program_start; break;
    case trigger::segment_mark: e = Event::segment_mark; break;
    case trigger::program_end: e = Event::program_end; break;
    default: return;  // user M-codes are recorded in the frame only
  }
  // The state machine formats a message on refusal; triggers are rare (a few per run),
  // not per sample.
  const Transition t = state_.handle(e);
  if (!t.accepted) {
    ++counters_.triggers_refused;
    return;
  }
  switch (t.action) {
    case Action::start_measurement:
      recorder_.discard();
      recorder_.start();
      ++counters_.measurements_started;
      break;
    case Action::stop_and_evaluate:
      recorder_.stop_after(posttrigger_frames_);
      ++counters_.measurements_completed;
      break;
    case Action::discard: recorder_.discard(); break;
    default: break;
  }
}

void MeasurementSession::on_frame(const Frame& frame) noexcept {
  Frame f = frame;
  ++counters_.frames;
  if (f.flags & frame_flag::gap_before) ++counters_.frames_lost;
  if (f.flags != 0) ++counters_.frames_flagged;
  // External triggers due at (or before) this sample are written into the frame, so the
  // recording carries them exactly like triggers from the DAQ's own trigger input.
  std::size_t keep = 0;
  int external = 0;
  for (std::size_t k = 0; k < pending_count_; ++k) {
    if (pending_[k].sample_index <= f.sample_index && external == 0) {
      if (pending_[k].sample_index < f.sample_index) ++counters_.triggers_late;
      external = pending_[k].code;
    } else {
      pending_[keep++] = pending_[k];
    }
  }
  pending_count_ = keep;
  if (f.trigger == 0 && external != 0) f.trigger = external;
  if (f.trigger == trigger::program_start)
    apply_trigger(trigger::program_start);  // start before the push: the M101 frame is recorded
  recorder_.push(f);
  if (f.trigger != trigger::none && f.trigger != trigger::program_start) apply_trigger(f.trigger);
  if (external != 0 && frame.trigger != 0 && external != frame.trigger) {
    // Two triggers on one sample: keep the DAQ's own in the frame, apply the other next
    // frame (re-queued at this index so it counts as late once).
    (void)queue_trigger(f.sample_index, external);
  }
}

bool MeasurementSession::close_now() noexcept {
  if (state_.state() == State::measuring) {
    if (!state_.handle(Event::program_end).accepted) return false;
    ++counters_.measurements_completed;
  } else if (!(state_.state() == State::evaluating && recorder_.recording())) {
    return false;  // nothing recording (or already complete)
  }
  recorder_.stop_after(0);
  return recorder_.complete();
}

Transition MeasurementSession::command(Event e, std::string_view reason) {
  const Transition t = state_.handle(e, reason);
  if (t.accepted && t.action == Action::discard) recorder_.discard();
  return t;
}

}  // namespace eical::dsp
