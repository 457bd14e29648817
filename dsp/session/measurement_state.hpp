#pragma once
// The measurement state machine of eicald:
//   IDLE → ARMED → MEASURING → EVALUATING → DONE, and FAULT (with a reason) from anywhere.
// Events come from NC triggers (M101 start/tare, M102 segment, M103 end — seed 003:
// M-functions tare, start and stop recording), HMI commands and the service itself.
// Pure logic: no clocks, no I/O. It lives in dsp/ (not daemon/) so that eicald and the
// offline tools (`eical demo`, replay) run the identical measurement logic.
#include <cstdint>
#include <string>
#include <string_view>

namespace eical::dsp {

enum class State { idle, armed, measuring, evaluating, done, fault };

enum class Event {
  arm,              // HMI/NC: prepare a measurement (optional; M101 arms implicitly)
  program_start,    // M101: tare (bias reference) and start recording
  segment_mark,     // M102: repeat / corner / target reached
  program_end,      // M103: stop recording, evaluate
  evaluation_done,  // the evaluation published its result
  abort,            // HMI: drop the current measurement, keep the recording
  reset,            // HMI: leave FAULT after the cause was fixed
  fault,            // the service detected a fault (source stopped, disk full, ...)
};

std::string_view to_string(State s);
std::string_view to_string(Event e);

// What the service must do because of a transition.
enum class Action { none, start_measurement, mark_segment, stop_and_evaluate, publish_done, discard, enter_fault };

struct Transition {
  State from;
  State to;
  Action action;
  bool accepted;  // false: the event is not allowed in this state (state unchanged)
  // Why it was refused, or the fault reason. Static text or the state machine's fault
  // reason (valid while it lives): a refusal on the DSP thread allocates nothing.
  std::string_view message;
};

class MeasurementState {
 public:
  [[nodiscard]] State state() const { return state_; }
  [[nodiscard]] const std::string& fault_reason() const { return fault_reason_; }
  [[nodiscard]] std::uint32_t segments() const { return segments_; }

  // `reason` is used with Event::fault.
  Transition handle(Event e, std::string_view reason = {});

 private:
  State state_ = State::idle;
  std::string fault_reason_;
  std::uint32_t segments_ = 0;
};

}  // namespace eical::dsp
