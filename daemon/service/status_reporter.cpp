#include "daemon/service/status_reporter.hpp"

#include "daemon/service/history_hook.hpp"
#include "daemon/service/hmi_link.hpp"
#include "daemon/system/log.hpp"

#include <chrono>
#include <cstdio>

namespace eical::daemon {

StatusReporter::StatusReporter(StatusSources sources, double rate_hz,
                               std::function<void(const ServiceStatus&)> on_status)
    : s_(std::move(sources)),
      rate_hz_(rate_hz),
      on_status_(std::move(on_status)),
      rate_(s_.fs_hz, s_.rate_too_slow_matters),
      thread_([this] { loop(); }) {}

StatusReporter::~StatusReporter() { stop(); }

void StatusReporter::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_.notify_one();
  thread_.join();
}

void StatusReporter::loop() {
  const auto period = std::chrono::duration<double>(1.0 / rate_hz_);
  std::unique_lock lk(mu_);
  while (!cv_.wait_for(lk, period, [&] { return stop_; })) {
    lk.unlock();
    const std::uint64_t frames = s_.counters->frames.load(std::memory_order_relaxed);
    // Progress of the DSP loop (or the run loop reopening a failed source) is what the
    // watchdog is fed on: a stalled DSP thread gets no status, and systemd restarts eicald.
    const bool progress = frames != last_frames_ || s_.counters->faulted.load();
    if (progress) report();
    last_frames_ = frames;
    watch_stall(progress);
    watch_rate();
    s_.source->drain_diagnostics([](const std::string& line) { log(LogLevel::info, "%s", line.c_str()); });
    lk.lock();
  }
}

void StatusReporter::watch_stall(bool progress) {
  ticks_without_progress_ = progress ? 0 : ticks_without_progress_ + 1;
  const double stalled_s = ticks_without_progress_ / rate_hz_;
  if (progress && stall_said_) {
    stall_said_ = false;
    log(LogLevel::notice, "frames are handled again");
    if (s_.on_stall) s_.on_stall("");
  }
  if (progress || stall_said_ || stalled_s < kStallS) return;
  stall_said_ = true;
  const std::size_t waiting = s_.ring->size_approx();
  const ServiceStatus st = collect();
  char why[256];
  if (waiting > 0)
    std::snprintf(why, sizeof why,
                  "the DSP thread has handled no frame for %.1f s while %zu wait in the ring (state %s, sample %lld)",
                  stalled_s, waiting, st.state.c_str(), static_cast<long long>(st.sample_index));
  else
    std::snprintf(why, sizeof why, "no frame from the source %.*s for %.1f s (state %s, sample %lld)",
                  static_cast<int>(s_.source->name().size()), s_.source->name().data(), stalled_s, st.state.c_str(),
                  static_cast<long long>(st.sample_index));
  log(LogLevel::error, "%s; the watchdog is not fed, systemd restarts eicald", why);
  if (s_.on_stall) s_.on_stall(why);
  std::lock_guard lk(report_mu_);
  publish_to_hmi(collect());  // the HMI sees why; systemd does not hear of it (no progress)
}

void StatusReporter::watch_rate() {
  if (!s_.watch_rate) return;
  ServiceCounters& k = *s_.counters;
  double ratio = 0.0;
  if (k.faulted.load())
    rate_.reset();  // reopening: the stamps start again
  else
    ratio = rate_.observe(k.stamp_index.load(std::memory_order_relaxed), k.stamp_ns.load(std::memory_order_relaxed));
  const double was = k.source_rate_ratio.exchange(ratio, std::memory_order_relaxed);
  if ((was == 0.0) == (ratio == 0.0)) return;
  if (ratio != 0.0)
    log(LogLevel::error,
        "source: delivers %.3g times the samples per second [acquisition] fs_hz = %.0f Hz says; measurements meanwhile "
        "are flagged source_rate",
        ratio, s_.fs_hz);
  else
    log(LogLevel::notice, "source: its rate is within %.0f %% of fs_hz again", SourceRateWatch::kTolerance * 100.0);
}

ServiceStatus StatusReporter::collect() const {
  const ServiceCounters& k = *s_.counters;
  constexpr auto relaxed = std::memory_order_relaxed;
  ServiceStatus st;
  const EvaluationStatus ev = s_.evaluator->status();
  st.state = k.faulted.load() ? "FAULT" : std::string(dsp::to_string(k.measurement_state()));
  st.fault = ev.fault;
  if (s_.history && st.fault.empty()) st.fault = s_.history->problem();
  if (const double r = k.source_rate_ratio.load(std::memory_order_relaxed); r != 0.0 && st.fault.empty()) {
    char b[160];
    std::snprintf(b, sizeof b, "source_rate: %.3g times the samples per second [acquisition] fs_hz = %.0f Hz says", r,
                  s_.fs_hz);
    st.fault = b;
  }
  st.frames = k.frames.load(relaxed);
  st.overruns = s_.ring->overruns();
  st.frames_lost = k.frames_lost.load(relaxed);
  st.measurements = k.measurements.load(relaxed);
  st.results_written = ev.results;
  st.last_result = ev.last_result;
  st.sample_index = k.sample_index.load(relaxed);
  st.sample_time_ns = s_.daq_clock->time_ns(st.sample_index);
  st.temp_table_c = k.temp_c[0].load(relaxed), st.temp_head_c = k.temp_c[1].load(relaxed);
  StatusCounters& c = st.counters;
  c.bad_frames = k.bad_frames.load(relaxed);
  c.frames_flagged = k.frames_flagged.load(relaxed);
  c.stamp_overruns = s_.source->stamp_overruns();
  c.triggers_late = k.triggers_late.load(relaxed);
  c.triggers_refused = k.triggers_refused.load(relaxed) + k.trigger_queue_full.load(relaxed);
  c.recorder_overflow = k.recorder_overflow.load(relaxed);
  c.handoffs_deferred = k.handoffs_deferred.load(relaxed);
  for (const auto* ch : s_.channels) {
    c.triggers_accepted += ch->accepted();
    c.triggers_refused += ch->refused() + ch->dropped();
  }
  for (const auto* l : s_.listeners) c.trigger_events_ignored += l->ignored();
  if (s_.hmi)
    c.live_overruns = s_.hmi->live_overruns(), c.dds_write_errors = s_.hmi->write_errors(),
    c.commands = s_.hmi->commands_received();
  const drivers::SourceCounters sc = s_.source->counters();
  c.source_decode_errors = sc.decode_errors, c.source_lost_samples = sc.lost_samples,
  c.source_dropped_frames = sc.dropped_frames;
  c.setpoint_samples = sc.setpoint_samples, c.setpoint_missing = sc.setpoint_missing;
  return st;
}

void StatusReporter::report() {
  std::lock_guard lk(report_mu_);
  const ServiceStatus st = collect();
  on_status_(st);
  publish_to_hmi(st);
}

void StatusReporter::publish_to_hmi(const ServiceStatus& st) {
  if (!s_.hmi) return;
  drivers::dds::StatusMsg m;
  m.state = st.state, m.fault = st.fault, m.frames = st.frames, m.overruns = st.overruns,
  m.frames_lost = st.frames_lost;
  m.measurements = st.measurements, m.results = st.results_written;
  m.sample_index = st.sample_index, m.sample_time_ns = st.sample_time_ns;
  m.temp_table_c = st.temp_table_c, m.temp_head_c = st.temp_head_c;
  m.counters = st.counters;
  const dsp::State state = s_.counters->faulted.load() ? dsp::State::fault : s_.counters->measurement_state();
  s_.hmi->set_status(m, state);
}

}  // namespace eical::daemon
