#pragma once
// Every counter of the service that the Status topic publishes, declared once: the list
// below makes the C++ message's fields, the copy to and from the idlc-generated type
// (a counter missing from eical.idl fails to compile; DdsStatusCounters.MatchTheIdl
// checks the other way), the round-trip test and `eical hmi`'s line. What each one counts
// is said once, in eical.idl's Status; where each is measured, in the daemon's
// StatusReporter::collect. Header only and free of DDS: the daemon and the tools use it.
#include <cstdint>

// X(name, trouble, label): `trouble` counters mean something was lost, repaired or
// refused, and `eical hmi` names them when they are not zero, by `label`.
#define EICAL_STATUS_COUNTERS(X)                                 \
  X(bad_frames, true, "bad frames")                              \
  X(live_overruns, true, "Live overruns")                        \
  X(stamp_overruns, true, "stamp overruns")                      \
  X(dds_write_errors, true, "DDS write errors")                  \
  X(triggers_accepted, false, "triggers accepted")               \
  X(triggers_refused, true, "triggers refused")                  \
  X(triggers_late, true, "triggers late")                        \
  X(trigger_events_ignored, true, "trigger events ignored")      \
  X(recorder_overflow, true, "recorder overflow")                \
  X(handoffs_deferred, false, "handoffs deferred")               \
  X(source_decode_errors, true, "decode errors")                 \
  X(source_lost_samples, true, "samples lost by the source")     \
  X(source_dropped_frames, true, "frames dropped by the source") \
  X(setpoint_samples, false, "set-point samples")                \
  X(setpoint_missing, true, "frames without set-point")          \
  X(frames_flagged, false, "frames flagged")                     \
  X(commands, false, "commands")

namespace eical::drivers::dds {

struct StatusCounters {
#define EICAL_STATUS_COUNTER_FIELD(name, trouble, label) std::uint64_t name = 0;
  EICAL_STATUS_COUNTERS(EICAL_STATUS_COUNTER_FIELD)
#undef EICAL_STATUS_COUNTER_FIELD
};

// One counter as a reader sees it.
struct StatusCounterView {
  const char* name;  // as in eical.idl
  const char* label;
  bool trouble;
  std::uint64_t value;
};

// Calls f(StatusCounterView) for every counter, in the list's order.
template <class F>
void for_each_counter(const StatusCounters& c, F&& f) {
#define EICAL_STATUS_COUNTER_VISIT(name, trouble, label) f(StatusCounterView{#name, label, trouble, c.name});
  EICAL_STATUS_COUNTERS(EICAL_STATUS_COUNTER_VISIT)
#undef EICAL_STATUS_COUNTER_VISIT
}

// Copies every counter between two structs that name them alike (the C++ message and the
// idlc-generated C type, either way).
template <class To, class From>
void copy_counters(To& to, const From& from) {
#define EICAL_STATUS_COUNTER_COPY(name, trouble, label) to.name = from.name;
  EICAL_STATUS_COUNTERS(EICAL_STATUS_COUNTER_COPY)
#undef EICAL_STATUS_COUNTER_COPY
}

// Pointers to every counter (the test that each travels by its own field).
inline constexpr std::uint64_t StatusCounters::*kStatusCounterFields[] = {
#define EICAL_STATUS_COUNTER_POINTER(name, trouble, label) &StatusCounters::name,
    EICAL_STATUS_COUNTERS(EICAL_STATUS_COUNTER_POINTER)
#undef EICAL_STATUS_COUNTER_POINTER
};

}  // namespace eical::drivers::dds
