#pragma once
// The status thread: at [dds] status_rate_hz it gathers every counter — the DSP thread's
// (atomics), the rings', the source's, the trigger inputs', the HMI link's and the
// evaluations' — into one ServiceStatus, hands it to systemd (on_status) and the HMI
// (Status topic), and writes the sources' diagnostic lines to the journal. Everything
// that formats, locks or writes once a second happens here, never on the DSP thread.
#include "daemon/service/evaluator.hpp"
#include "daemon/service/service.hpp"
#include "daemon/service/service_counters.hpp"
#include "daemon/service/source_rate_watch.hpp"
#include "daemon/triggers/trigger_listener.hpp"
#include "drivers/acquisition/pump.hpp"
#include "drivers/source/sample_clock.hpp"
#include "drivers/source/stamped_source.hpp"

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace eical::daemon {

class HmiLink;
class HistoryHook;

struct StatusSources {
  ServiceCounters* counters = nullptr;  // the status thread writes source_rate_ratio only
  const drivers::FrameRing* ring = nullptr;
  drivers::StampedSource* source = nullptr;
  const drivers::SampleClock* daq_clock = nullptr;
  const Evaluator* evaluator = nullptr;
  HmiLink* hmi = nullptr;
  const HistoryHook* history = nullptr;  // [history] enabled: its problem is the fault when none other is
  std::vector<const TriggerChannel*> channels;
  std::vector<const TriggerListener*> listeners;
  // No frame handled for kStallS while the source is not being reopened: called once with
  // what is stalled (the DSP thread, frames waiting in the ring; or the source, none
  // arriving), and with "" when frames flow again.
  std::function<void(const std::string&)> on_stall;
  // The source's rate against fs_hz (live sources only; DAQs also when too slow).
  bool watch_rate = false, rate_too_slow_matters = false;
  double fs_hz = 0.0;
};

class StatusReporter {
 public:
  StatusReporter(StatusSources sources, double rate_hz, std::function<void(const ServiceStatus&)> on_status);
  ~StatusReporter();  // stop()
  // Stops the thread; report() may still be called (the last word at the end).
  void stop();
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

  // The status now (any thread); `report()` also hands it on, as the thread does (calls
  // from several threads are serialised: on_status never runs twice at once).
  [[nodiscard]] ServiceStatus collect() const;
  void report();

  static constexpr double kStallS = 1.0;  // well inside systemd's WatchdogSec (5 s)

 private:
  void loop();
  // A tick without progress: how long it lasts, said once; progress again: said once.
  void watch_stall(bool progress);
  // The delivered rate from the acquisition stamps; said when it goes off and comes back.
  void watch_rate();
  // Status to the HMI only: systemd's watchdog is fed on progress (on_status), not on this.
  void publish_to_hmi(const ServiceStatus& st);

  StatusSources s_;
  double rate_hz_;
  std::function<void(const ServiceStatus&)> on_status_;
  std::uint64_t last_frames_ = 0;
  int ticks_without_progress_ = 0;
  bool stall_said_ = false;
  SourceRateWatch rate_;
  std::mutex report_mu_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace eical::daemon
