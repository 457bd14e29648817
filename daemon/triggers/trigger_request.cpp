#include "daemon/triggers/trigger_request.hpp"

namespace eical::daemon {

std::string describe(const TriggerVerdict& v, int code) {
  const std::string m = "M" + std::to_string(code);
  const std::string state = std::string(dsp::to_string(v.state));
  switch (v.refusal) {
    case Refusal::none: return m + " accepted at sample " + std::to_string(v.sample_index) + " of the DAQ clock";
    case Refusal::measurement_running:
      return m + " refused: a measurement is running (state " + state + "); it continues untouched — M103 ends it";
    case Refusal::no_measurement:
      return m + " refused: no measurement is running (state " + state + "); M101 starts one";
    case Refusal::busy: return m + " refused: the previous measurement is still being evaluated (state " + state + ")";
    case Refusal::fault: return m + " refused: the service is in FAULT (see Status.fault)";
    case Refusal::queue_full: return m + " refused: too many triggers pending";
    case Refusal::time_ahead:
      return m + " refused: its time lies more than " + std::to_string(static_cast<int>(kMaxTriggerAheadS)) +
             " s beyond the newest frame (time_ns must be CLOCK_MONOTONIC of eicald's host, or 0 for now)";
  }
  return m + " refused";
}

}  // namespace eical::daemon
