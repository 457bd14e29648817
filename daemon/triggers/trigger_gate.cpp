#include "daemon/triggers/trigger_gate.hpp"

namespace eical::daemon {

void TriggerGate::on_frame(std::int64_t sample_index) noexcept {
  std::size_t keep = 0;
  // The session applies at most one external trigger per frame: keep a margin of the queue's length.
  for (std::size_t k = 0; k < count_; ++k)
    if (queued_[k].sample_index + static_cast<std::int64_t>(queued_.size()) >= sample_index)
      queued_[keep++] = queued_[k];
  count_ = keep;
}

TriggerVerdict TriggerGate::decide(const TriggerRequest& r, std::int64_t sample_index, dsp::State state) noexcept {
  using dsp::State;
  // The state once the triggers already queued are applied.
  State s = state;
  for (std::size_t k = 0; k < count_; ++k) {
    if (queued_[k].code == kProgramStart && (s == State::idle || s == State::done || s == State::armed))
      s = State::measuring;
    // A measurement ended by a queued M103 is handed over at once (the evaluator is
    // normally free): the next program may be queued behind it.
    else if (queued_[k].code == kProgramEnd && s == State::measuring)
      s = State::done;
  }
  TriggerVerdict v;
  v.id = r.id;
  v.sample_index = sample_index;
  v.state = s;
  if (s == State::fault)
    v.refusal = Refusal::fault;
  else if (r.code == kProgramStart && s == State::measuring)
    v.refusal = Refusal::measurement_running;
  else if (r.code == kProgramStart && s == State::evaluating)
    v.refusal = Refusal::busy;
  else if ((r.code == kSegmentMark || r.code == kProgramEnd) && s != State::measuring)
    v.refusal = Refusal::no_measurement;
  else if (count_ == queued_.size())
    v.refusal = Refusal::queue_full;
  v.accepted = v.refusal == Refusal::none;
  if (v.accepted) queued_[count_++] = {sample_index, r.code};
  return v;
}

}  // namespace eical::daemon
