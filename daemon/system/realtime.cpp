#include "daemon/system/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace eical::daemon {

RealtimeOutcome lock_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {true, "memory locked (mlockall)"};
  const int err = errno;
  return {false, std::string("mlockall refused (") + std::strerror(err) +
                     "): page faults may delay samples; grant CAP_IPC_LOCK or raise LimitMEMLOCK"};
}

RealtimeOutcome make_this_thread_realtime(int priority, const char* thread_name) {
  ::pthread_setname_np(::pthread_self(), thread_name);
  if (priority <= 0) return {true, std::string(thread_name) + ": normal scheduling (configured)"};
  sched_param param{};
  param.sched_priority = priority;
  const int err = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  if (err == 0) return {true, std::string(thread_name) + ": SCHED_FIFO priority " + std::to_string(priority)};
  return {false, std::string(thread_name) + ": SCHED_FIFO refused (" + std::strerror(err) +
                     "), running with normal scheduling; grant CAP_SYS_NICE for real-time priority"};
}

}  // namespace eical::daemon
