#pragma once
// An NC trigger (M101 tare + start, M102 segment, M103 stop) from an input that is not the
// DAQ's own trigger channel (DDS Command, GPIO edge, CAN frame), and the DSP thread's
// verdict on it. Plain data: they travel through SPSC rings.
#include "dsp/core/frame.hpp"
#include "dsp/session/measurement_state.hpp"

#include <cmath>
#include <cstdint>
#include <string>

namespace eical::daemon {

inline constexpr int kProgramStart = dsp::trigger::program_start, kSegmentMark = dsp::trigger::segment_mark,
                     kProgramEnd = dsp::trigger::program_end;
inline bool is_nc_trigger(int code) { return dsp::trigger::is_nc_trigger(code); }

struct TriggerRequest {
  std::uint32_t id = 0;      // per input, echoed in the verdict
  std::int64_t time_ns = 0;  // CLOCK_MONOTONIC when the M-code ran (0 = now)
  int code = 0;
  double p = std::nan("");  // M101: program number (P word); NaN = absent
};

// Why the DSP thread did not accept a trigger.
enum class Refusal : std::uint8_t {
  none,
  measurement_running,  // M101 while a measurement runs: it continues untouched
  no_measurement,       // M102/M103 without a running measurement
  busy,                 // M101 while the previous measurement still waits for its evaluation
  fault,                // the service is in FAULT
  queue_full,           // more triggers pending than the session holds
  time_ahead,           // its time lies far beyond the newest frame (not CLOCK_MONOTONIC?)
};

// An external trigger's time may lie this far beyond the newest frame (frames held back for
// the servo stream arrive up to [setpoint.servo_stream] hold_ms after their trigger); one
// further ahead would wait in the queue for hours, blocking every later M101 meanwhile.
inline constexpr double kMaxTriggerAheadS = 10.0;

struct TriggerVerdict {
  std::uint32_t id = 0;
  bool accepted = false;
  Refusal refusal = Refusal::none;
  std::int64_t sample_index = 0;        // where it lands (accepted) on the DAQ clock
  dsp::State state = dsp::State::idle;  // the measurement state projected at that sample
};

// "M101 refused: a measurement is running (since sample 1234); M103 ends it" — for a Reply
// or the journal (not on the DSP thread).
std::string describe(const TriggerVerdict& v, int code);

}  // namespace eical::daemon
