#include "daemon/service/service.hpp"

#include "daemon/service/hmi_link.hpp"
#include "daemon/system/log.hpp"
#include "daemon/system/realtime.hpp"
#include "drivers/acquisition/pump.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/source/replay_source.hpp"
#include "drivers/source/sim_source.hpp"
#include "drivers/usb_daq/usb_daq_source.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"
#include "sim/scenario.hpp"
#include "drivers/results/result_json.hpp"

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

}  // namespace

Service::Service(DaemonConfig config) : config_(std::move(config)) {}
Service::~Service() = default;

std::unique_ptr<drivers::Source> Service::make_source(const DaemonConfig& c) {
  const drivers::Pacing pacing = c.source.pacing == "realtime" ? drivers::Pacing::realtime : drivers::Pacing::free_running;
  if (c.source.kind == "replay") {
    auto run = std::make_shared<const dsp::Run>(drivers::read_run(c.source.replay_run));
    return std::make_unique<drivers::ReplaySource>(run, pacing, "replay");
  }
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
  // The daemon's configuration is what the service believes about its hardware.
  sc.meta.acquisition = c.acquisition;
  sc.meta.site = c.site;
  sc.meta.machine = c.machine;
  sc.meta.sensors[0] = c.sensors[0];
  sc.meta.sensors[1] = c.sensors[1];
  for (int s = 0; s < 2; ++s) sc.truth[s].spec = c.sensors[s];
  return std::make_unique<drivers::SimSource>(
      sc, drivers::SimSourceOptions{pacing, c.source.sim_repeat_program, c.source.sim_idle_s});
}

void Service::run(const std::atomic<bool>& stop, const std::function<void(const ServiceStatus&)>& on_status) {
  auto source = make_source(config_);
  source->open();
  const dsp::RunMeta meta = source->meta();
  log(LogLevel::info, "source %.*s open: %.0f Hz", static_cast<int>(source->name().size()), source->name().data(), meta.acquisition.fs_hz);

  drivers::FrameRing ring(config_.limits.ring_capacity_frames);
  dsp::SessionConfig scfg;
  scfg.fs_hz = meta.acquisition.fs_hz;
  scfg.max_measurement_s = config_.limits.max_measurement_s;
  dsp::MeasurementSession session(scfg);
  dsp::Pipeline live(dsp::pipeline_config(meta, session.recorder_capacity()));

  // The HMI bus; without it the service still measures and records (and says so).
  std::unique_ptr<HmiLink> hmi;
  try {
    hmi = std::make_unique<HmiLink>(config_.dds, "eicald@" + config_.machine.name);
    log(LogLevel::info, "dds: publishing on domain %d", config_.dds.domain_id);
  } catch (const std::exception& e) {
    log(LogLevel::warning, "dds unavailable, running without the HMI bus: %s", e.what());
  }
  const bool dds_triggers = std::find(config_.triggers.inputs.begin(), config_.triggers.inputs.end(), "dds") != config_.triggers.inputs.end();
  // DAQ clock ↔ CLOCK_MONOTONIC: the DSP thread notes (sample index, time) as frames
  // arrive; a trigger's time maps onto the sample that was due then.
  std::int64_t clock_index = 0, clock_ns = 0;
  const double fs = meta.acquisition.fs_hz;
  const auto live_every = static_cast<std::uint64_t>(std::max(1.0, fs / config_.dds.live_rate_hz));

  // Evaluation thread: takes finished recordings, writes them and their result.
  std::mutex mu;
  std::condition_variable cv;
  std::vector<dsp::Frame> pending, spare;
  spare.reserve(session.recorder_capacity());
  bool have_pending = false, spare_ready = true, quit = false;
  ServiceStatus status;
  std::mutex status_mu;
  std::thread evaluator([&] {
    for (;;) {
      std::vector<dsp::Frame> frames;
      {
        std::unique_lock lk(mu);
        cv.wait(lk, [&] { return have_pending || quit; });
        if (!have_pending) return;
        frames.swap(pending);
        have_pending = false;
      }
      dsp::Run run;
      run.meta = meta;
      run.meta.id = "eicald-" + utc_now("%Y%m%dT%H%M%SZ") + "-" + std::to_string(frames.empty() ? 0 : frames.front().sample_index);
      run.meta.created = utc_now("%Y-%m-%dT%H:%M:%SZ");
      run.channels.psd_count = 0;
      run.frames = std::move(frames);
      const auto dir = config_.recording.dir / run.meta.id;
      std::string error;
      try {
        drivers::write_run(run, dir, {.gzip = config_.recording.gzip, .overwrite = false});
        const dsp::Analysis a = dsp::analyze_run(run);
        drivers::write_result(run, a, dir / "result.json");
        if (hmi) {
          drivers::dds::ResultMsg r;
          r.program_id = run.meta.id;
          r.program = run.meta.program.kind;
          r.degraded = a.degraded;
          if (a.circle) r.circular_deviation_G_um = a.circle->circular_deviation_G_um, r.radius_mean_deviation_um = a.circle->radius_mean_deviation_um;
          r.json = drivers::result_json(run, a).dump();
          hmi->publish_result(r);
        }
        log(LogLevel::notice, "measurement %s written (%zu frames)%s", run.meta.id.c_str(), run.frames.size(), a.degraded ? ", result degraded" : "");
      } catch (const std::exception& e) {
        error = e.what();
        log(LogLevel::error, "recording %s: %s", run.meta.id.c_str(), e.what());
      }
      {
        std::lock_guard lk(status_mu);
        if (error.empty()) ++status.results_written, status.last_result = (dir / "result.json").string();
        else status.fault = error;
      }
      // Hand the storage back to the DSP thread (its capacity is kept).
      run.frames.clear();
      std::lock_guard lk(mu);
      spare = std::move(run.frames);
      if (spare.capacity() < session.recorder_capacity()) spare.reserve(session.recorder_capacity());
      spare_ready = true;
    }
  });

  if (config_.realtime.mlockall) {
    const auto r = lock_memory();
    log(r.ok ? LogLevel::info : LogLevel::warning, "%s", r.message.c_str());
  }
  const auto rt = make_this_thread_realtime(config_.realtime.sched_fifo_priority, "eicald-dsp");
  log(rt.ok ? LogLevel::info : LogLevel::warning, "%s", rt.message.c_str());

  auto last_status = std::chrono::steady_clock::now();
  std::uint64_t frames = 0;
  const auto stats = drivers::pump(*source, ring, [&](const dsp::Frame& f) {
    if ((frames & 63) == 0) {
      timespec ts{};
      clock_gettime(CLOCK_MONOTONIC, &ts);
      clock_index = f.sample_index;
      clock_ns = static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
    }
    if (hmi && dds_triggers) {
      TriggerRequest t;
      while (hmi->pop_trigger(t)) {
        const std::int64_t idx = t.time_ns > 0 ? clock_index + static_cast<std::int64_t>(static_cast<double>(t.time_ns - clock_ns) * 1e-9 * fs)
                                               : f.sample_index;
        (void)session.queue_trigger(std::max(idx, f.sample_index), t.code);
      }
    }
    session.on_frame(f);
    if (session.state().state() == dsp::State::measuring || f.trigger == 103) live.step(f);
    ++frames;
    if (hmi && frames % live_every == 0) {
      const auto& l = live.live();
      LiveSample s{l.sample_index, {l.pos_mm.x(), l.pos_mm.y(), l.pos_mm.z()}, {l.vel_mm_s.x(), l.vel_mm_s.y(), l.vel_mm_s.z()}, l.integrating};
      hmi->push_live(s);
    }
    if (session.measurement_ready()) {
      std::unique_lock lk(mu, std::try_to_lock);  // never wait on the evaluator
      if (lk.owns_lock() && spare_ready && !have_pending && session.take(spare)) {
        pending.swap(spare);
        have_pending = true;
        spare_ready = false;
        lk.unlock();
        cv.notify_one();
        session.evaluation_done();
        live.reset();  // ready for the next M101, storage kept
      }
    }
    if ((frames & 1023) == 0) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_status >= std::chrono::seconds(1)) {
        last_status = now;
        ServiceStatus s;
        {
          std::lock_guard lk(status_mu);
          s = status;
        }
        s.state = std::string(dsp::to_string(session.state().state()));
        s.frames = frames;
        s.overruns = ring.overruns();
        s.frames_lost = session.counters().frames_lost;
        s.measurements = session.counters().measurements_completed;
        on_status(s);
        if (hmi) {
          drivers::dds::StatusMsg m;
          m.state = s.state, m.fault = s.fault, m.frames = s.frames, m.overruns = s.overruns, m.frames_lost = s.frames_lost;
          m.measurements = s.measurements, m.results = s.results_written;
          m.temp_table_c = f.temp_c[0], m.temp_head_c = f.temp_c[1];
          hmi->set_status(m);
          hmi->set_state(s.state);
        }
      }
    }
  }, stop);
  {
    std::lock_guard lk(mu);
    quit = true;
  }
  cv.notify_one();
  evaluator.join();
  if (!stats.source_error.empty()) throw drivers::SourceError(stats.source_error);
  log(LogLevel::info, "stopped: %llu frames, %llu overruns", static_cast<unsigned long long>(stats.frames_read),
      static_cast<unsigned long long>(stats.overruns));
}

}  // namespace eical::daemon
