#pragma once
// The faults of issue 21, each injected into the real service (in this process, or eicald
// as a child process) and measured: tests/faults asserts on each outcome, bench_faults
// prints them as the fault table. Every case runs in a scratch directory of its own and
// on a DDS domain of its own, so cases and other tests on the host do not meet.
#include "tests/faults/harness/fault_outcome.hpp"

#include <functional>
#include <string>
#include <vector>

namespace eical::faults {

// The disk fills up while a measurement is recorded (files may not grow past 64 KiB:
// RLIMIT_FSIZE, EFBIG as ENOSPC), then space is freed.
FaultOutcome disk_full_mid_recording();
// The recording directory is removed while the service runs.
FaultOutcome recording_dir_removed();
// The wall clock steps back: the run ids the new measurement would get are taken.
FaultOutcome wall_clock_steps_back();
// A DAQ (daq_stream) delivering three times faster than real time, then at its rate.
FaultOutcome source_faster_than_real_time();
// A DAQ that stops sending for 2 s in the middle of a measurement.
FaultOutcome source_stalls();
// An HMI sending Command at 1 kHz for 5 s while the service measures.
FaultOutcome command_flood();
// Commands that are malformed (wall-clock times, unknown codes and actions) or oversized.
FaultOutcome malformed_commands();
// eicald is killed (SIGKILL) while it writes a run; then started again.
FaultOutcome kill9_during_write();
// eicald's DSP thread hangs; systemd's watchdog (played by the case) ends it and starts it again.
FaultOutcome dsp_thread_hung();

struct FaultCase {
  const char* name;
  FaultOutcome (*run)();
};
// Every case, in the order of the table.
const std::vector<FaultCase>& all_cases();

}  // namespace eical::faults
