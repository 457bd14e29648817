#include "dsp/session/measurement_state.hpp"

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

Transition MeasurementState::handle(Event e, std::string_view reason) {
  const State from = state_;
  auto go = [&](State to, Action a, std::string msg = {}) {
    state_ = to;
    return Transition{from, to, a, true, std::move(msg)};
  };
  auto refuse = [&] {
    return Transition{from, from, Action::none, false,
                      std::string(to_string(e)) + " is not allowed in state " + std::string(to_string(from))};
  };

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
      // A second M101 without M103: the NC program was restarted. Start over.
      if (e == Event::program_start) {
        segments_ = 0;
        return go(State::measuring, Action::start_measurement, "program restarted without M103");
      }
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
