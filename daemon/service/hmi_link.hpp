#pragma once
// eicald's side of the HMI bus: a publisher thread (Status at status_rate_hz, Live
// samples handed over by the DSP thread through an SPSC ring, Results and Traces as they
// are written) and a command thread (Command topic → NC triggers for the DSP thread, Reply).
// The DSP thread only touches the two rings and an eventfd that wakes the publisher the
// moment a Live sample is there (no lock, allocation or DDS call on the DSP thread; the
// publisher sleeps on the eventfd, not on a timer, so Live latency is not a tick).
#include "daemon/config/daemon_config.hpp"
#include "drivers/dds/bus.hpp"
#include "drivers/ring/spsc_ring.hpp"

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace eical::daemon {

struct LiveSample {
  std::int64_t sample_index;
  double pos_mm[3], vel_mm_s[3];
  bool integrating;
  std::int64_t acquired_ns;  // CLOCK_MONOTONIC when the acquisition thread had the sample
};

struct TriggerRequest {
  std::int64_t time_ns;  // CLOCK_MONOTONIC when the M-code ran (0 = now)
  int code;
};

class HmiLink {
 public:
  // Throws dds::BusError when the bus cannot start (bad CYCLONEDDS_URI, no network).
  // publisher_priority: SCHED_FIFO of the Live/Status publisher (0 = normal), below the
  // DSP thread's so that it never delays the sample path but is not queued behind
  // ordinary work on a loaded control PC.
  HmiLink(const DdsConfig& config, std::string daemon_name, int publisher_priority = 0);
  ~HmiLink();

  // DSP thread.
  void push_live(const LiveSample& s) noexcept;
  bool pop_trigger(TriggerRequest& t) noexcept { return triggers_.try_pop(t); }

  // Any thread (copied under a mutex; called at 1 Hz and per result).
  void set_status(const drivers::dds::StatusMsg& s);
  void publish_result(const drivers::dds::ResultMsg& r);
  void publish_trace(const drivers::dds::TraceMsg& t);
  // The current measurement state for command replies.
  void set_state(const std::string& state);

  [[nodiscard]] std::uint64_t commands_received() const { return commands_.load(); }

 private:
  void publisher();
  void commander();

  DdsConfig config_;
  std::string name_;
  std::unique_ptr<drivers::dds::Bus> bus_;
  drivers::SpscRing<LiveSample> live_{1024};
  drivers::SpscRing<TriggerRequest> triggers_{64};
  std::mutex mu_;
  drivers::dds::StatusMsg status_;
  std::string state_ = "IDLE";
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> commands_{0};
  int publisher_priority_ = 0;
  int wake_fd_ = -1;  // eventfd: DSP thread → publisher
  std::thread publisher_, commander_;
  std::deque<std::pair<std::string, std::uint32_t>> recent_triggers_;  // commander thread: (sender, request id)
};

}  // namespace eical::daemon
