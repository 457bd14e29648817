#pragma once
// eicald's shell around the shared core: source → acquisition thread → SPSC ring → DSP
// thread (measurement session + live pipeline) → evaluation thread (recorder write,
// analysis, result.json). The DSP thread never blocks on disk: finished recordings leave
// it by buffer swap and are written by the evaluation thread.
#include "daemon/config/daemon_config.hpp"

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

namespace eical::drivers {
class Source;
}

namespace eical::daemon {

struct ServiceStatus {
  std::string state;             // IDLE, ARMED, MEASURING, EVALUATING, DONE, FAULT
  std::string fault;             // reason when FAULT or the last write error
  std::uint64_t frames = 0, overruns = 0, frames_lost = 0;
  std::uint64_t measurements = 0, results_written = 0;
  std::string last_result;       // path of the last result.json
  std::int64_t sample_index = 0, sample_time_ns = 0;  // DAQ clock ↔ CLOCK_MONOTONIC
};

class Service {
 public:
  explicit Service(DaemonConfig config);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // Opens the configured source (SourceError when the hardware is absent), then runs
  // until `stop` is set or the source ends. A source that fails later is reopened every
  // retry_s (state FAULT meanwhile). A measurement cut short by the stop or the failure
  // is still recorded and evaluated, flagged `interrupted` or `source_stopped`.
  // `on_status` is called about once a second from the DSP thread's side (cheap: copies
  // counters) and while waiting to reopen the source.
  void run(const std::atomic<bool>& stop, const std::function<void(const ServiceStatus&)>& on_status);

  // Builds the configured source (sim, replay, usb_daq, wrapped in the fault injector
  // when [source.fault] asks for it); exposed for `--check`.
  static std::unique_ptr<drivers::Source> make_source(const DaemonConfig& config);

 private:
  DaemonConfig config_;
};

}  // namespace eical::daemon
