#pragma once
// Real-time set-up for the acquisition and DSP threads: SCHED_FIFO and mlockall when the
// process may (CAP_SYS_NICE, CAP_IPC_LOCK — granted by systemd/eicald.service), a clear
// warning and normal scheduling when not. Never fatal: a desktop test run still works.
#include <string>

namespace eical::daemon {

struct RealtimeOutcome {
  bool ok = false;
  std::string message;  // what was done, or why not
};

// Locks current and future pages so a page fault never stalls the sample path.
RealtimeOutcome lock_memory();
// Gives the calling thread SCHED_FIFO at `priority` (1..99); 0 keeps normal scheduling.
RealtimeOutcome make_this_thread_realtime(int priority, const char* thread_name);

}  // namespace eical::daemon
