#include "daemon/service/service.hpp"

#include "daemon/config/linuxcnc_source_config.hpp"
#include "daemon/service/evaluator.hpp"
#include "daemon/service/frame_guard.hpp"
#include "daemon/service/frame_loop.hpp"
#include "daemon/service/history_hook.hpp"
#include "daemon/service/hmi_link.hpp"
#include "daemon/service/preflight.hpp"
#include "daemon/service/recording_cleanup.hpp"
#include "daemon/service/recording_handoff.hpp"
#include "daemon/service/service_counters.hpp"
#include "daemon/service/status_reporter.hpp"
#include "daemon/service/stop_record.hpp"
#include "daemon/system/log.hpp"
#include "daemon/system/realtime.hpp"
#include "daemon/triggers/trigger_listener.hpp"
#include "drivers/acquisition/pump.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/source/fault_source.hpp"
#include "drivers/source/replay_source.hpp"
#include "drivers/source/servo_setpoint_source.hpp"
#include "drivers/source/sim_factory.hpp"
#include "drivers/source/stamped_source.hpp"
#include "drivers/usb_daq/daq_stream_source.hpp"
#include "drivers/usb_daq/usb_daq_source.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace eical::daemon {
namespace {

bool has_input(const TriggerConfig& t, const char* input) {
  return std::find(t.inputs.begin(), t.inputs.end(), input) != t.inputs.end();
}

std::unique_ptr<drivers::Source> make_sim_source(const DaemonConfig& c, drivers::Pacing pacing) {
  return drivers::make_sim_source(sim_machine(c), {pacing, c.source.sim_repeat_program, c.source.sim_idle_s});
}

// The frames' origin: a DAQ, a simulator, a recording, or LinuxCNC driving the simulator.
std::unique_ptr<drivers::Source> make_sensor_source(const DaemonConfig& c) {
  const drivers::Pacing pacing =
      c.source.pacing == "realtime" ? drivers::Pacing::realtime : drivers::Pacing::free_running;
  if (c.source.kind == "replay") {
    auto run = std::make_shared<const dsp::Run>(drivers::read_run(c.source.replay_run));
    return std::make_unique<drivers::ReplaySource>(run, pacing, "replay");
  }
  if (c.source.kind == "linuxcnc") return make_linuxcnc_source(c);
  if (c.source.kind == "usb_daq")
    return std::make_unique<drivers::UsbDaqSource>(hardware_meta(c), drivers::parse_usb_id(c.source.usb_id));
  if (c.source.kind == "daq_stream") {
    const auto& d = c.source.daq_stream;
    return std::make_unique<drivers::DaqStreamSource>(
        hardware_meta(c), drivers::DaqStreamOptions{d.path, d.connect_timeout_s, d.stall_timeout_s});
  }
  return make_sim_source(c, pacing);
}

struct SourceChain {
  std::unique_ptr<drivers::Source> source;
  const drivers::ServoSetPointSource* servo = nullptr;  // when the set-point is LinuxCNC's servo stream
};

// Sensors (fault-injected when asked), then the NC's servo set-point beside a DAQ.
SourceChain build_source(const DaemonConfig& c) {
  SourceChain chain;
  chain.source = make_sensor_source(c);
  if (c.source.fault.any())
    chain.source = std::make_unique<drivers::FaultSource>(std::move(chain.source), c.source.fault);
  if (c.setpoint.source == "servo_stream") {
    drivers::ServoSetPointOptions o;
    o.stream.fifo = c.setpoint.servo_fifo;
    o.stream.servo_rate_hz = c.setpoint.servo_rate_hz;
    o.hold_s = c.setpoint.hold_ms * 1e-3;
    auto servo = std::make_unique<drivers::ServoSetPointSource>(std::move(chain.source), o);
    chain.servo = servo.get();
    chain.source = std::move(servo);
  }
  return chain;
}

// Everything one run of the service holds, built stage by stage (destroyed in reverse:
// the status thread first, the source last).
struct Parts {
  explicit Parts(const DaemonConfig& c) : config(c) {}
  const DaemonConfig& config;
  std::unique_ptr<drivers::StampedSource> source;
  const drivers::ServoSetPointSource* servo = nullptr;
  dsp::RunMeta meta;
  dsp::AnalysisOptions analysis;
  std::string sensor_calibration = "datasheet";  // what the results were compensated with (history, Result)
  std::unique_ptr<HmiLink> hmi;
  std::unique_ptr<HistoryHook> history;
  std::vector<std::unique_ptr<TriggerChannel>> channels;  // hardware inputs
  std::vector<std::unique_ptr<TriggerListener>> listeners;
  std::unique_ptr<drivers::FrameRing> ring;
  std::unique_ptr<RecordingStream> recording;  // the session's frames to the recording thread
  std::unique_ptr<dsp::MeasurementSession> session;
  std::unique_ptr<dsp::Pipeline> live;
  std::unique_ptr<FrameGuard> guard;
  std::unique_ptr<RecordingHandoff> handoff;
  ServiceCounters counters;
  std::unique_ptr<Evaluator> evaluator;
  std::unique_ptr<FrameLoop> loop;
  std::unique_ptr<StatusReporter> reporter;
  std::vector<std::filesystem::path> unevaluated;  // runs of an earlier start without result.json
  std::unique_ptr<StopRecord> stop_record;         // how the previous eicald ended; how this one stalls
  std::string stall;                               // what is stalled now (status thread)
};

void open_source(Parts& p) {
  SourceChain chain = build_source(p.config);
  p.servo = chain.servo;
  p.source = std::make_unique<drivers::StampedSource>(std::move(chain.source));
  p.source->open();  // absent hardware: a clear error at start, not a retry loop
  p.meta = p.source->meta();
  log(LogLevel::info, "source %.*s open: %.0f Hz", static_cast<int>(p.source->name().size()), p.source->name().data(),
      p.meta.acquisition.fs_hz);
  if (p.config.source.is_daq() && p.config.setpoint.source == "none")
    log(LogLevel::warning,
        "no NC set-point ([setpoint] source = \"none\"): recordings carry no cmd_* and are evaluated as free form");
}

// The identified calibration (eical identify) replaces the data sheet for the live path,
// the recordings and their evaluation; a file that cannot be read stops the start.
void apply_calibration(Parts& p) {
  if (p.config.calibration_file.empty()) return;
  const drivers::SensorCalibration cal = drivers::read_sensor_calibration(p.config.calibration_file, p.meta);
  drivers::apply_calibration(cal, p.meta, p.analysis);
  p.sensor_calibration = cal.method + ": " + p.config.calibration_file.string() + " (run " + cal.run_id + ")";
  log(LogLevel::info, "calibration %s (%s, from run %s) in use", p.config.calibration_file.c_str(), cal.method.c_str(),
      cal.run_id.c_str());
}

// What must hold before measuring: refused at start, naming the cause.
void check_machine(Parts& p) {
  if (auto problem = dds_config_problem(p.config.dds)) throw std::runtime_error(*problem);
  if (auto problem = setpoint_problem(p.config.setpoint)) throw std::runtime_error(*problem);
  // Reported (Status.fault, journal), not refused: measuring goes on, every write retries.
  if (auto problem = recording_dir_problem(p.config.recording.dir)) log(LogLevel::error, "%s", problem->c_str());
}

// What an interrupted start left in the recording directory: temporaries removed, runs
// moved aside restored, runs without result.json handed to the evaluator.
void clean_recording(Parts& p) {
  RecordingCleanup c = clean_recording_dir(p.config.recording.dir);
  if (c.removed + c.restored > 0)
    log(LogLevel::notice, "recording: %zu temporaries of an interrupted write removed, %zu runs restored, in %s",
        c.removed, c.restored, p.config.recording.dir.c_str());
  if (!c.unevaluated.empty())
    log(LogLevel::notice, "recording: %zu runs without result.json are evaluated now", c.unevaluated.size());
  p.unevaluated = std::move(c.unevaluated);
}

// The previous eicald did not stop cleanly (the watchdog, a crash, kill -9): said at once,
// and in Status.fault until another error replaces it (report_previous_stop).
void read_stop_record(Parts& p) {
  p.stop_record = std::make_unique<StopRecord>(p.config.recording.dir);
  if (const auto& previous = p.stop_record->previous()) log(LogLevel::error, "%s", previous->c_str());
}

void report_previous_stop(Parts& p) {
  if (const auto& previous = p.stop_record->previous()) p.evaluator->set_fault("restarted: " + *previous);
}

// The HMI bus; without it the service still measures and records (and says so).
void start_hmi(Parts& p) {
  try {
    const int rt = p.config.realtime.sched_fifo_priority;
    p.hmi = std::make_unique<HmiLink>(p.config.dds, "eicald@" + p.config.machine.name, rt > 10 ? rt - 10 : 0);
    log(LogLevel::info, "dds: publishing on domain %d", p.config.dds.domain_id);
  } catch (const std::exception& e) {
    if (has_input(p.config.triggers, "dds"))
      log(LogLevel::error, "dds unavailable, NC triggers over DDS cannot arrive: %s", e.what());
    else
      log(LogLevel::warning, "dds unavailable, running without the HMI bus: %s", e.what());
  }
}

// GPIO lines and CAN: opened now (an absent device stops the start, naming it).
void open_trigger_inputs(Parts& p, const TriggerInputFactory& factory) {
  for (auto& input : factory(p.config.triggers)) {
    log(LogLevel::info, "trigger input %s open", input->name().c_str());
    p.channels.push_back(std::make_unique<TriggerChannel>(input->name()));
    p.listeners.push_back(std::make_unique<TriggerListener>(std::move(input), *p.channels.back()));
  }
}

void make_measurement(Parts& p) {
  const auto& c = p.config;
  p.ring = std::make_unique<drivers::FrameRing>(c.limits.ring_capacity_frames);
  dsp::SessionConfig scfg;
  scfg.fs_hz = p.meta.acquisition.fs_hz;
  scfg.max_measurement_s = c.limits.max_measurement_s;
  // Recordings go to disk as they are measured: a ring as long as the acquisition's is all
  // the DSP thread holds of them, whatever their length.
  p.recording = std::make_unique<RecordingStream>(c.limits.ring_capacity_frames);
  p.session = std::make_unique<dsp::MeasurementSession>(scfg, p.recording.get());
  dsp::PipelineConfig live_cfg = dsp::pipeline_config(p.meta, p.session->recorder_capacity());
  for (int s = 0; s < 2; ++s) live_cfg.calibration[s] = p.analysis.calibration[s];
  // The live estimate only: the evaluation runs its own pipeline over the recording, so the
  // live one keeps no trace (it kept 104 B a sample, 620 MB for ten minutes, locked).
  live_cfg.trace = dsp::TraceKeeping::live;
  p.live = std::make_unique<dsp::Pipeline>(live_cfg);
  p.guard = std::make_unique<FrameGuard>(static_cast<float>(p.meta.sensors[0].temp_ref_c),
                                         static_cast<float>(p.meta.sensors[1].temp_ref_c));
  p.handoff = std::make_unique<RecordingHandoff>(*p.recording);
}

// The calibration history ([history]): results leave through an on-disk spool, never lost.
void start_history(Parts& p) {
  if (p.config.history.enabled) p.history = std::make_unique<HistoryHook>(p.config.history, p.sensor_calibration);
}

void start_evaluator(Parts& p, const std::atomic<bool>& stop) {
  EvaluatorLinks links;
  links.hmi = p.hmi.get(), links.servo = p.servo, links.history = p.history.get(), links.stop = &stop;
  links.unevaluated = std::move(p.unevaluated);
  links.sensor_calibration = p.sensor_calibration;
  p.evaluator = std::make_unique<Evaluator>(p.config, p.meta, p.analysis, *p.recording, *p.handoff, std::move(links));
  if (auto problem = recording_dir_problem(p.config.recording.dir)) p.evaluator->set_fault(*problem);
}

void make_frame_loop(Parts& p) {
  FrameLoopOptions o;
  o.fs_hz = p.meta.acquisition.fs_hz;
  o.frame_triggers = has_input(p.config.triggers, "frame");
  o.live_every = static_cast<std::uint64_t>(std::max(1.0, o.fs_hz / p.config.dds.live_rate_hz));
  p.loop =
      std::make_unique<FrameLoop>(o, *p.source, *p.session, *p.live, *p.guard, *p.handoff, p.counters, p.hmi.get());
  if (p.hmi && has_input(p.config.triggers, "dds")) p.loop->add_channel(p.hmi->triggers());
  for (auto& ch : p.channels) p.loop->add_channel(*ch);
}

void start_status(Parts& p, const std::function<void(const ServiceStatus&)>& on_status) {
  StatusSources s;
  s.counters = &p.counters;
  s.ring = p.ring.get();
  s.source = p.source.get();
  s.daq_clock = &p.loop->daq_clock();
  s.evaluator = p.evaluator.get();
  s.hmi = p.hmi.get();
  s.history = p.history.get();
  if (p.hmi) s.channels.push_back(&p.hmi->triggers());
  for (const auto& ch : p.channels) s.channels.push_back(ch.get());
  for (const auto& l : p.listeners) s.listeners.push_back(l.get());
  s.watch_rate = p.source->backpressure() == drivers::Backpressure::drop_newest;  // a live source
  s.rate_too_slow_matters = p.config.source.is_daq();
  s.fs_hz = p.meta.acquisition.fs_hz;
  // A stall is written down before systemd's watchdog ends this eicald: the next one says why.
  s.on_stall = [&p](const std::string& why) {
    p.stop_record->running(why);
    if (!why.empty())
      p.evaluator->set_fault("stalled: " + why);
    else
      p.evaluator->clear_fault("stalled: " + p.stall);
    p.stall = why;
  };
  p.reporter = std::make_unique<StatusReporter>(std::move(s), p.config.dds.status_rate_hz, on_status);
}

void enter_realtime(const Parts& p) {
  if (p.config.realtime.mlockall) {
    const auto r = lock_memory();
    log(r.ok ? LogLevel::info : LogLevel::warning, "%s", r.message.c_str());
  }
  const auto rt = make_this_thread_realtime(p.config.realtime.sched_fifo_priority, "eicald-dsp");
  log(rt.ok ? LogLevel::info : LogLevel::warning, "%s", rt.message.c_str());
}

// A measurement the data ended inside is kept: recorded, evaluated and flagged.
dsp::Flag end_cause(const drivers::PumpStats& stats) {
  if (stats.stopped)
    return {dsp::FlagCode::interrupted,
            {},
            "the service was stopped during the measurement; frames up to the stop are kept"};
  return {dsp::FlagCode::source_stopped, {}, stats.source_error};  // empty: the code's default
}

// The source failed: FAULT with the reason (Status, journal), reopened every retry_s.
// False when the service was stopped meanwhile.
bool reopen_source(Parts& p, const std::string& error, const std::atomic<bool>& stop) {
  log(LogLevel::error, "source failed: %s; reopening every %.1f s", error.c_str(), p.config.source.retry_s);
  (void)p.session->command(dsp::Event::fault, error);
  p.evaluator->set_fault("source: " + error);
  p.counters.faulted.store(true);
  bool reopened = false;
  while (!reopened && !stop.load()) {
    p.reporter->report();  // FAULT with its reason at once, not at the next status tick
    // A retry timer, not a data poll: SIGTERM is noticed within one step.
    const auto step = std::chrono::duration<double>(std::min(p.config.source.retry_s, 1.0));
    for (double waited = 0; waited < p.config.source.retry_s && !stop.load(); waited += step.count())
      std::this_thread::sleep_for(step);
    if (stop.load()) break;
    try {
      p.source->open();
      reopened = true;
    } catch (const std::exception& e) {
      p.evaluator->set_fault(std::string("source: ") + e.what());
    }
  }
  if (!reopened) return false;
  p.loop->continue_after_reopen();
  (void)p.session->command(dsp::Event::reset);
  p.counters.faulted.store(false);
  log(LogLevel::notice, "source reopened; measuring resumes at the next M101");
  return true;
}

// [source.fault] hang_dsp_at_s: the DSP thread stops handling frames, as a hung
// computation would, until the service is stopped (a test of the watchdog path).
void hang_if_injected(const Parts& p, const dsp::Frame& f, const std::atomic<bool>& stop) {
  const double at_s = p.config.source.fault.hang_dsp_at_s;
  if (at_s < 0.0 || static_cast<double>(f.sample_index) < at_s * p.meta.acquisition.fs_hz || stop.load()) return;
  log(LogLevel::warning, "injected fault: the DSP thread hangs at sample %lld ([source.fault] hang_dsp_at_s)",
      static_cast<long long>(f.sample_index));
  while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

// The acquisition thread fills the ring, this (the DSP) thread runs the frame loop, until
// the stop or the end of the data; a failed source is reopened.
void acquire(Parts& p, const std::atomic<bool>& stop) {
  p.stop_record->running();
  for (;;) {
    const drivers::PumpStats stats = drivers::pump(
        *p.source, *p.ring,
        [&](const dsp::Frame& f) {
          hang_if_injected(p, f, stop);
          p.loop->on_frame(f);
        },
        stop);
    p.loop->close_measurement(end_cause(stats));
    if (stats.stopped || stats.source_error.empty()) return;
    if (!reopen_source(p, stats.source_error, stop)) return;
  }
}

void finish(Parts& p) {
  p.reporter->stop();
  p.evaluator->finish();
  p.reporter->report();  // the last word: results and errors included
  p.stop_record->stopped_cleanly();
  log(LogLevel::info, "stopped: %llu frames, %llu overruns", static_cast<unsigned long long>(p.counters.frames.load()),
      static_cast<unsigned long long>(p.ring->overruns()));
}

}  // namespace

Service::Service(DaemonConfig config) : config_(std::move(config)), trigger_inputs_(&daemon::open_trigger_inputs) {}
Service::~Service() = default;

std::unique_ptr<drivers::Source> Service::make_source(const DaemonConfig& config) {
  return build_source(config).source;
}

void Service::run(const std::atomic<bool>& stop, const std::function<void(const ServiceStatus&)>& on_status) {
  Parts p(config_);
  open_source(p);
  apply_calibration(p);
  check_machine(p);
  clean_recording(p);
  read_stop_record(p);
  start_hmi(p);
  open_trigger_inputs(p, trigger_inputs_);
  make_measurement(p);
  start_history(p);
  start_evaluator(p, stop);
  report_previous_stop(p);
  make_frame_loop(p);
  start_status(p, on_status);
  enter_realtime(p);
  acquire(p, stop);
  finish(p);
}

}  // namespace eical::daemon
