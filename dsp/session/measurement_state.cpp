#include "dsp/session/measurement_state.hpp"

#include <array>
#include <string>

namespace eical::dsp {

std::string_view to_string(State s) {
  switch (s) {
    case State::idle: return "IDLE";
    case State::armed: return "ARMED";
    case State::measuring: return "MEASURING";
    case State::evaluating: return "EVALUATING";
    case State::done: return "DONE";
    case State::fault: return "FAULT";
  }
  return "?";
}

std::string_view to_string(Event e) {
  switch (e) {
    case Event::arm: return "arm";
    case Event::program_start: return "program_start (M101)";
    case Event::segment_mark: return "segment_mark (M102)";
    case Event::program_end: return "program_end (M103)";
    case Event::evaluation_done: return "evaluation_done";
    case Event::abort: return "abort";
    case Event::reset: return "reset";
    case Event::fault: return "fault";
  }
  return "?";
}

namespace {

constexpr int kStates = 6, kEvents = 8;

// "program_end (M103) is not allowed in state IDLE" for every pair, built once before
// main() so that a refusal on the DSP thread only points at it.
const std::array<std::array<std::string, kEvents>, kStates> kRefusals = [] {
  std::array<std::array<std::string, kEvents>, kStates> t;
  for (int s = 0; s < kStates; ++s)
    for (int e = 0; e < kEvents; ++e)
      t[static_cast<std::size_t>(s)][static_cast<std::size_t>(e)] = std::string(to_string(static_cast<Event>(e))) +
                                                                    " is not allowed in state " +
                                                                    std::string(to_string(static_cast<State>(s)));
  // The one refusal an NC meets in normal operation says what happens next.
  t[static_cast<std::size_t>(State::measuring)][static_cast<std::size_t>(Event::program_start)] =
      "program_start (M101) is not allowed in state MEASURING: the running measurement continues untouched (M103 ends "
      "it, abort drops it)";
  return t;
}();

std::string_view refusal(State s, Event e) {
  const auto si = static_cast<std::size_t>(s), ei = static_cast<std::size_t>(e);
  if (si >= kRefusals.size() || ei >= kRefusals[0].size()) return "not allowed";
  return kRefusals[si][ei];
}

}  // namespace

Transition MeasurementState::handle(Event e, std::string_view reason) {
  const State from = state_;
  auto go = [&](State to, Action a, std::string_view msg = {}) {
    state_ = to;
    return Transition{from, to, a, true, msg};
  };
  auto refuse = [&] { return Transition{from, from, Action::none, false, refusal(from, e)}; };

  if (e == Event::fault) {
    fault_reason_ = reason.empty() ? "unspecified fault" : std::string(reason);
    return go(State::fault, Action::enter_fault, fault_reason_);
  }
  switch (from) {
    case State::idle:
    case State::done:
      if (e == Event::arm) return go(State::armed, Action::none);
      if (e == Event::program_start) {  // M101 arms implicitly: the NC need not send "arm"
        segments_ = 0;
        return go(State::measuring, Action::start_measurement);
      }
      if (e == Event::abort) return go(State::idle, Action::none);
      return refuse();
    case State::armed:
      if (e == Event::program_start) {
        segments_ = 0;
        return go(State::measuring, Action::start_measurement);
      }
      if (e == Event::arm) return go(State::armed, Action::none);
      if (e == Event::abort) return go(State::idle, Action::none);
      return refuse();
    case State::measuring:
      if (e == Event::segment_mark) {
        ++segments_;
        return go(State::measuring, Action::mark_segment);
      }
      if (e == Event::program_end) return go(State::evaluating, Action::stop_and_evaluate);
      if (e == Event::abort) return go(State::idle, Action::discard);
      // A second M101 is refused: splitting the running measurement would leave two
      // broken ones. An NC program restarted after a reset sends abort, or M103 first.
      return refuse();
    case State::evaluating:
      if (e == Event::evaluation_done) return go(State::done, Action::publish_done);
      if (e == Event::abort) return go(State::idle, Action::discard);
      return refuse();
    case State::fault:
      if (e == Event::reset) {
        fault_reason_.clear();
        return go(State::idle, Action::none);
      }
      return refuse();
  }
  return refuse();
}

}  // namespace eical::dsp
