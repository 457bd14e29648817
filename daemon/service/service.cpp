#include "daemon/service/service.hpp"

#include "daemon/config/linuxcnc_source_config.hpp"
#include "daemon/service/frame_guard.hpp"
#include "daemon/service/history_hook.hpp"
#include "daemon/service/hmi_link.hpp"
#include "daemon/service/trace_builder.hpp"
#include "daemon/system/log.hpp"
#include "daemon/system/realtime.hpp"
#include "drivers/acquisition/pump.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/source/replay_source.hpp"
#include "drivers/source/sim_source.hpp"
#include "drivers/source/stamped_source.hpp"
#include "drivers/usb_daq/usb_daq_source.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"
#include "sim/scenario.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/results/software_version.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <ctime>
#include <mutex>
#include <thread>

namespace eical::daemon {
namespace {

// UTC now in a strftime format: "%Y%m%dT%H%M%SZ" for run ids, RFC 3339 for run.toml.
std::string utc_now(const char* format) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, format, &tm);
  return b;
}

bool has_input(const TriggerConfig& t, const char* input) {
  return std::find(t.inputs.begin(), t.inputs.end(), input) != t.inputs.end();
}

std::unique_ptr<drivers::Source> make_base_source(const DaemonConfig& c) {
  const drivers::Pacing pacing = c.source.pacing == "realtime" ? drivers::Pacing::realtime : drivers::Pacing::free_running;
  if (c.source.kind == "replay") {
    auto run = std::make_shared<const dsp::Run>(drivers::read_run(c.source.replay_run));
    return std::make_unique<drivers::ReplaySource>(run, pacing, "replay");
  }
  if (c.source.kind == "linuxcnc") return make_linuxcnc_source(c);
  if (c.source.kind == "usb_daq") {
    dsp::RunMeta meta;
    meta.acquisition = c.acquisition;
    meta.site = c.site;
    meta.machine = c.machine;
    meta.sensors[0] = c.sensors[0];
    meta.sensors[1] = c.sensors[1];
    meta.psd = c.psd;
    meta.program.kind = "freeform";
    return std::make_unique<drivers::UsbDaqSource>(meta, drivers::parse_usb_id(c.source.usb_id));
  }
  sim::Scenario sc = c.source.sim_program == "circle"
                         ? sim::circle_scenario(c.source.sim_radius_mm, c.source.sim_feed_mm_min, c.source.sim_repeats, "ccw", c.source.sim_seed)
                         : sim::step_scenario(0.0, 50.0, c.source.sim_feed_mm_min, c.source.sim_repeats, c.source.sim_seed);
  // A program file (eical gen-nc --meta): the simulated NC runs its G-code.
  if (c.source.sim_program_loaded) sc.meta.program = *c.source.sim_program_loaded;
  // The daemon's configuration is what the service believes about its hardware.
  sc.meta.acquisition = c.acquisition;
  sc.meta.site = c.site;
  sc.meta.machine = c.machine;
  sc.meta.sensors[0] = c.sensors[0];
  sc.meta.sensors[1] = c.sensors[1];
  sc.meta.psd = c.psd;  // the strips the simulated machine carries
  for (int s = 0; s < 2; ++s) sc.truth[s].spec = c.sensors[s];
  return std::make_unique<drivers::SimSource>(
      sc, drivers::SimSourceOptions{pacing, c.source.sim_repeat_program, c.source.sim_idle_s});
}

// A recording handed from the DSP thread to the evaluation thread, with what the DSP
// thread knows about it that the frames do not say.
struct Job {
  std::vector<dsp::Frame> frames;
  std::string cause;                  // empty, or why it ended without M103 (a quality flag)
  std::uint64_t nonfinite_frames = 0; // frames whose NaN/Inf channels the guard replaced
};

}  // namespace

Service::Service(DaemonConfig config) : config_(std::move(config)) {}
Service::~Service() = default;

std::unique_ptr<drivers::Source> Service::make_source(const DaemonConfig& c) {
  auto base = make_base_source(c);
  if (c.source.fault.any()) return std::make_unique<drivers::FaultSource>(std::move(base), c.source.fault);
  return base;
}

void Service::run(const std::atomic<bool>& stop, const std::function<void(const ServiceStatus&)>& on_status) {
  drivers::StampedSource source(make_source(config_));
  source.open();  // absent hardware: a clear error at start, not a retry loop
  dsp::RunMeta meta = source.meta();
  log(LogLevel::info, "source %.*s open: %.0f Hz", static_cast<int>(source.name().size()), source.name().data(), meta.acquisition.fs_hz);
  // The identified calibration (eical identify) replaces the data sheet for the live path,
  // the recordings and their evaluation; a file that cannot be read stops the start.
  dsp::AnalysisOptions analysis;
  std::string sensor_calibration = "datasheet";  // what the results were compensated with (history, Result)
  if (!config_.calibration_file.empty()) {
    const drivers::SensorCalibration cal = drivers::read_sensor_calibration(config_.calibration_file, meta);
    drivers::apply_calibration(cal, meta, analysis);
    sensor_calibration = cal.method + ": " + config_.calibration_file.string() + " (run " + cal.run_id + ")";
    log(LogLevel::info, "calibration %s (%s, from run %s) in use", config_.calibration_file.c_str(), cal.method.c_str(), cal.run_id.c_str());
  }

  drivers::FrameRing ring(config_.limits.ring_capacity_frames);
  dsp::SessionConfig scfg;
  scfg.fs_hz = meta.acquisition.fs_hz;
  scfg.max_measurement_s = config_.limits.max_measurement_s;
  dsp::MeasurementSession session(scfg);
  dsp::PipelineConfig live_cfg = dsp::pipeline_config(meta, session.recorder_capacity());
  for (int s = 0; s < 2; ++s) live_cfg.calibration[s] = analysis.calibration[s];
  dsp::Pipeline live(live_cfg);
  FrameGuard guard(static_cast<float>(meta.sensors[0].temp_ref_c), static_cast<float>(meta.sensors[1].temp_ref_c));

  // The HMI bus; without it the service still measures and records (and says so).
  std::unique_ptr<HmiLink> hmi;
  try {
    const int rt = config_.realtime.sched_fifo_priority;
    hmi = std::make_unique<HmiLink>(config_.dds, "eicald@" + config_.machine.name, rt > 10 ? rt - 10 : 0);
    log(LogLevel::info, "dds: publishing on domain %d", config_.dds.domain_id);
  } catch (const std::exception& e) {
    log(LogLevel::warning, "dds unavailable, running without the HMI bus: %s", e.what());
  }
  // The calibration history ([history]): results leave through an on-disk spool, never lost.
  std::unique_ptr<HistoryHook> history;
  if (config_.history.enabled) history = std::make_unique<HistoryHook>(config_.history, sensor_calibration);
  const bool dds_triggers = has_input(config_.triggers, "dds");
  // Without the "frame" input the DAQ's trigger channel is ignored (the NC sends its
  // M-codes another way; a floating trigger line must not start measurements).
  const bool frame_triggers = has_input(config_.triggers, "frame");
  // DAQ clock ↔ CLOCK_MONOTONIC from the acquisition stamps: a trigger's time maps onto
  // the sample that was acquired then.
  std::int64_t clock_index = 0, clock_ns = 0;
  const double fs = meta.acquisition.fs_hz;
  const auto live_every = static_cast<std::uint64_t>(std::max(1.0, fs / config_.dds.live_rate_hz));

  // Evaluation thread: takes finished recordings, writes them and their result.
  std::mutex mu;
  std::condition_variable cv, cv_back;
  std::vector<dsp::Frame> pending, spare;
  spare.reserve(session.recorder_capacity());
  std::string pending_cause;
  std::uint64_t pending_nonfinite = 0;
  bool have_pending = false, spare_ready = true, quit = false;
  ServiceStatus status;
  std::mutex status_mu;
  std::thread evaluator([&] {
    for (;;) {
      Job job;
      {
        std::unique_lock lk(mu);
        cv.wait(lk, [&] { return have_pending || quit; });
        if (!have_pending) return;
        job.frames.swap(pending);
        job.cause.swap(pending_cause);
        job.nonfinite_frames = pending_nonfinite;
        have_pending = false;
      }
      dsp::Run run;
      run.meta = meta;
      run.meta.id = "eicald-" + utc_now("%Y%m%dT%H%M%SZ") + "-" + std::to_string(job.frames.empty() ? 0 : job.frames.front().sample_index);
      run.meta.created = utc_now("%Y-%m-%dT%H:%M:%SZ");
      run.channels.psd_count = static_cast<int>(std::min<std::size_t>(meta.psd.size(), dsp::kMaxPsd));
      run.frames = std::move(job.frames);
      const auto dir = config_.recording.dir / run.meta.id;
      std::string error;
      try {
        // The run first: what was measured is durable before anything can fail.
        drivers::write_run(run, dir, {.gzip = config_.recording.gzip, .overwrite = false});
        dsp::Analysis a = dsp::analyze_run(run, analysis);
        if (!job.cause.empty()) a.flags.push_back(job.cause), a.degraded = true;
        if (job.nonfinite_frames > 0) {
          a.flags.push_back("not_finite: " + std::to_string(job.nonfinite_frames) +
                            " frames had NaN/Inf in a temperature or set-point channel (last finite value held)");
          a.degraded = true;
        }
        drivers::write_result(run, a, dir / "result.json");
        if (history) history->append(run, a, dir);
        if (hmi) {
          drivers::dds::ResultMsg r;
          r.machine = run.meta.machine.name;
          r.program_id = run.meta.id;
          r.measured_at = run.meta.created, r.run_path = dir.string(), r.software_version = drivers::software_version();
          r.sensor_calibration = sensor_calibration;
          r.program = run.meta.program.kind;
          r.degraded = a.degraded;
          if (a.circle) r.circular_deviation_G_um = a.circle->circular_deviation_G_um, r.radius_mean_deviation_um = a.circle->radius_mean_deviation_um;
          r.json = drivers::result_json(run, a).dump();
          hmi->publish_result(r);
          if (auto t = make_trace(run, a, config_.dds.trace_max_points)) hmi->publish_trace(*t);
        }
        log(LogLevel::notice, "measurement %s written (%zu frames)%s", run.meta.id.c_str(), run.frames.size(), a.degraded ? ", result degraded" : "");
      } catch (const std::exception& e) {
        error = e.what();
        log(LogLevel::error, "recording %s: %s", run.meta.id.c_str(), e.what());
      }
      {
        std::lock_guard lk(status_mu);
        if (error.empty()) ++status.results_written, status.last_result = (dir / "result.json").string();
        else status.fault = "recording: " + error;
      }
      // Hand the storage back to the DSP thread (its capacity is kept).
      run.frames.clear();
      {
        std::lock_guard lk(mu);
        spare = std::move(run.frames);
        if (spare.capacity() < session.recorder_capacity()) spare.reserve(session.recorder_capacity());
        spare_ready = true;
      }
      cv_back.notify_one();
    }
  });

  // DSP thread → evaluation thread. Live: never waits (try_lock; the recording stays
  // complete in the session until the next frame). At the end of the data it may wait.
  std::uint64_t meas_nonfinite = 0;
  auto hand_over = [&](bool may_wait, const std::string* cause) {
    std::unique_lock lk(mu, std::defer_lock);
    if (may_wait) {
      lk.lock();
      cv_back.wait(lk, [&] { return spare_ready && !have_pending; });
    } else if (!lk.try_lock() || !spare_ready || have_pending) {
      return;
    }
    if (!session.take(spare)) return;
    pending.swap(spare);
    if (cause) pending_cause = *cause;
    pending_nonfinite = meas_nonfinite;
    have_pending = true;
    spare_ready = false;
    lk.unlock();
    cv.notify_one();
    session.evaluation_done();
    live.reset();  // ready for the next M101, storage kept
  };

  auto report = [&](const std::string& state) {
    ServiceStatus s;
    {
      std::lock_guard lk(status_mu);
      s = status;
    }
    s.state = state;
    if (history && s.fault.empty()) s.fault = history->problem();
    s.frames = session.counters().frames;
    s.overruns = ring.overruns();
    s.frames_lost = session.counters().frames_lost;
    s.measurements = session.counters().measurements_completed;
    s.sample_index = clock_index, s.sample_time_ns = clock_ns;
    on_status(s);
    if (hmi) {
      drivers::dds::StatusMsg m;
      m.state = s.state, m.fault = s.fault, m.frames = s.frames, m.overruns = s.overruns, m.frames_lost = s.frames_lost;
      m.measurements = s.measurements, m.results = s.results_written;
      m.sample_index = s.sample_index, m.sample_time_ns = s.sample_time_ns;
      hmi->set_status(m);
      hmi->set_state(s.state);
    }
  };

  if (config_.realtime.mlockall) {
    const auto r = lock_memory();
    log(r.ok ? LogLevel::info : LogLevel::warning, "%s", r.message.c_str());
  }
  const auto rt = make_this_thread_realtime(config_.realtime.sched_fifo_priority, "eicald-dsp");
  log(rt.ok ? LogLevel::info : LogLevel::warning, "%s", rt.message.c_str());

  auto last_status = std::chrono::steady_clock::now();
  std::uint64_t frames = 0, started_seen = 0;
  // After a reopened source restarts its sample clock, the DAQ clock continues: indices
  // are offset past the last one seen and the first new frame is flagged gap_before.
  std::int64_t index_offset = 0, last_index = -1;
  bool gap_after_reopen = false;
  auto consume = [&](const dsp::Frame& in) {
    const std::int64_t acquired_ns = source.acquired_ns(in.sample_index);
    dsp::Frame f = in;
    f.sample_index += index_offset;
    if (gap_after_reopen) f.flags |= dsp::frame_flag::gap_before, gap_after_reopen = false;
    last_index = f.sample_index;
    if (!frame_triggers) f.trigger = 0;
    const bool nonfinite = guard.apply(f);
    if (acquired_ns != 0) clock_index = source.current_stamp().last_index + index_offset, clock_ns = acquired_ns;
    if (hmi && dds_triggers) {
      TriggerRequest t;
      while (hmi->pop_trigger(t)) {
        const std::int64_t idx = t.time_ns > 0 && clock_ns > 0
                                     ? clock_index + static_cast<std::int64_t>(static_cast<double>(t.time_ns - clock_ns) * 1e-9 * fs)
                                     : f.sample_index;
        (void)session.queue_trigger(std::max(idx, f.sample_index), t.code);
      }
    }
    session.on_frame(f);
    if (session.counters().measurements_started != started_seen) started_seen = session.counters().measurements_started, meas_nonfinite = 0;
    const bool measuring = session.state().state() == dsp::State::measuring;
    if (nonfinite && measuring) ++meas_nonfinite;
    if (measuring || f.trigger == 103) live.step(f);
    ++frames;
    if (hmi && frames % live_every == 0) {
      const auto& l = live.live();
      hmi->push_live({f.sample_index, {l.pos_mm.x(), l.pos_mm.y(), l.pos_mm.z()}, {l.vel_mm_s.x(), l.vel_mm_s.y(), l.vel_mm_s.z()},
                      l.integrating, acquired_ns});
    }
    if (session.measurement_ready()) hand_over(false, nullptr);
    if ((frames & 1023) == 0) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_status >= std::chrono::seconds(1)) {
        last_status = now;
        report(std::string(dsp::to_string(session.state().state())));  // 1 Hz, off the per-sample path
      }
    }
  };

  drivers::PumpStats stats;
  for (;;) {
    stats = drivers::pump(source, ring, consume, stop);
    // A measurement the data ended inside is kept: recorded, evaluated and flagged.
    const std::string cause =
        stats.stopped ? std::string("interrupted: the service was stopped during the measurement; frames up to the stop are kept")
        : !stats.source_error.empty() ? "source_stopped: " + stats.source_error
                                      : std::string("source_stopped: the source ended during the measurement");
    if (session.close_now() || session.measurement_ready()) hand_over(true, &cause);
    if (stats.stopped || stats.source_error.empty()) break;

    // The source failed: FAULT with the reason (Status, journal) and reopen it every retry_s.
    log(LogLevel::error, "source failed: %s; reopening every %.1f s", stats.source_error.c_str(), config_.source.retry_s);
    (void)session.command(dsp::Event::fault, stats.source_error);
    {
      std::lock_guard lk(status_mu);
      status.fault = "source: " + stats.source_error;
    }
    bool reopened = false;
    while (!reopened && !stop.load()) {
      report("FAULT");
      // A retry timer, not a data poll: SIGTERM is noticed within one step.
      const auto step = std::chrono::duration<double>(std::min(config_.source.retry_s, 1.0));
      for (double waited = 0; waited < config_.source.retry_s && !stop.load(); waited += step.count()) std::this_thread::sleep_for(step);
      if (stop.load()) break;
      try {
        source.open();
        reopened = true;
      } catch (const std::exception& e) {
        std::lock_guard lk(status_mu);
        status.fault = std::string("source: ") + e.what();
      }
    }
    if (!reopened) break;
    source.reset_lookup();
    index_offset = last_index + 1;
    gap_after_reopen = true;
    live.reset();
    (void)session.command(dsp::Event::reset);
    log(LogLevel::notice, "source reopened; measuring resumes at the next M101");
  }
  {
    std::lock_guard lk(mu);
    quit = true;
  }
  cv.notify_one();
  evaluator.join();
  report(std::string(dsp::to_string(session.state().state())));  // the last word: results and errors included
  log(LogLevel::info, "stopped: %llu frames, %llu overruns", static_cast<unsigned long long>(session.counters().frames),
      static_cast<unsigned long long>(ring.overruns()));
}

}  // namespace eical::daemon
