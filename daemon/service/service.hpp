#pragma once
// eicald's shell around the shared core: source → acquisition thread → SPSC ring → DSP
// thread (measurement session + live pipeline) → evaluation thread (recorder write,
// analysis, result.json). The DSP thread never blocks on disk: finished recordings leave
// it by buffer swap and are written by the evaluation thread.
#include "daemon/config/daemon_config.hpp"
#include "daemon/triggers/trigger_input.hpp"
#include "drivers/dds/status_counters.hpp"

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

// Every other counter of the service, as the Status topic publishes them.
using StatusCounters = drivers::dds::StatusCounters;

struct ServiceStatus {
  std::string state;  // IDLE, ARMED, MEASURING, EVALUATING, DONE, FAULT
  std::string fault;  // reason when FAULT or the last write error
  std::uint64_t frames = 0, overruns = 0, frames_lost = 0;
  std::uint64_t measurements = 0, results_written = 0;
  std::string last_result;                            // path of the last result.json
  std::int64_t sample_index = 0, sample_time_ns = 0;  // DAQ clock ↔ CLOCK_MONOTONIC
  float temp_table_c = 0.0f, temp_head_c = 0.0f;      // the sensors' case temperatures now
  StatusCounters counters;
};

class Service {
 public:
  explicit Service(DaemonConfig config);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // Opens the configured source and trigger inputs (SourceError / std::runtime_error
  // naming the absent device), then runs until `stop` is set or the source ends. A source
  // that fails later is reopened every retry_s (state FAULT meanwhile). A measurement cut
  // short by the stop or the failure is still recorded and evaluated, flagged
  // `interrupted` or `source_stopped`. `on_status` is called at [dds] status_rate_hz from
  // the status thread while frames flow or the source is being reopened (never from the
  // DSP thread), and once more at the end.
  void run(const std::atomic<bool>& stop, const std::function<void(const ServiceStatus&)>& on_status);

  // Builds the configured source (sim, replay, usb_daq, daq_stream, linuxcnc; next to a
  // DAQ the servo set-point; wrapped in the fault injector when [source.fault] asks for
  // it); exposed for `--check`.
  static std::unique_ptr<drivers::Source> make_source(const DaemonConfig& config);

  // Tests: hardware trigger inputs from elsewhere (a socketpair for CAN, an event source
  // for GPIO) instead of the devices [triggers] names.
  void set_trigger_inputs(TriggerInputFactory factory) { trigger_inputs_ = std::move(factory); }

 private:
  DaemonConfig config_;
  TriggerInputFactory trigger_inputs_;
};

}  // namespace eical::daemon
