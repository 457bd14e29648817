#pragma once
// eicald's side of the HMI bus: a publisher thread (Status at status_rate_hz, Live
// samples handed over by the DSP thread through an SPSC ring, Results as they are
// written) and a command thread (Command topic → NC triggers for the DSP thread, Reply).
// The DSP thread only touches the two rings: no DDS call, lock or allocation there.
#include "daemon/config/daemon_config.hpp"
#include "drivers/dds/bus.hpp"
#include "drivers/ring/spsc_ring.hpp"

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace eical::daemon {

struct LiveSample {
  std::int64_t sample_index;
  double pos_mm[3], vel_mm_s[3];
  bool integrating;
};

struct TriggerRequest {
  std::int64_t time_ns;  // CLOCK_MONOTONIC when the M-code ran (0 = now)
  int code;
};

class HmiLink {
 public:
  // Throws dds::BusError when the bus cannot start (bad CYCLONEDDS_URI, no network).
  HmiLink(const DdsConfig& config, std::string daemon_name);
  ~HmiLink();

  // DSP thread.
  void push_live(const LiveSample& s) noexcept { (void)live_.push_or_drop(s); }
  bool pop_trigger(TriggerRequest& t) noexcept { return triggers_.try_pop(t); }

  // Any thread (copied under a mutex; called at 1 Hz and per result).
  void set_status(const drivers::dds::StatusMsg& s);
  void publish_result(const drivers::dds::ResultMsg& r);
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
  std::thread publisher_, commander_;
};

}  // namespace eical::daemon
