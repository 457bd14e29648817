#include "daemon/service/evaluator.hpp"

#include "daemon/service/history_hook.hpp"
#include "daemon/service/hmi_link.hpp"
#include "daemon/service/trace_builder.hpp"
#include "daemon/system/log.hpp"
#include "drivers/exec/thread_for.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/results/software_version.hpp"
#include "drivers/run_io/file_spill.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_stream.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/setpoint/program_catalog.hpp"
#include "drivers/setpoint/program_setpoint.hpp"
#include "drivers/source/servo_setpoint_source.hpp"
#include "dsp/align/accel_lag.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/stream/analyze_stream.hpp"
#include "history/record/utc_time.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <optional>

namespace eical::daemon {
namespace {

using history::utc_now;  // "%Y%m%dT%H%M%SZ" for run ids, RFC 3339 for run.toml

std::string percent(double ratio) { return std::to_string(static_cast<int>(std::lround(ratio * 100.0))) + " %"; }

// [limits] temp_min_c, temp_max_c: a present sensor's case temperature outside them
// (its compensation is specified within them) flags the result.
std::vector<dsp::Flag> temperature_flags(const dsp::Run& run, const RecordingStats& stats, const Limits& limits) {
  std::vector<dsp::Flag> flags;
  const char* names[2] = {"table", "head"};
  for (int s = 0; s < 2; ++s) {
    if (!run.meta.sensor_present[s]) continue;
    const float lo = stats.temp_lo_c[s], hi = stats.temp_hi_c[s];
    if (!(lo <= hi) || (static_cast<double>(lo) >= limits.temp_min_c && static_cast<double>(hi) <= limits.temp_max_c))
      continue;
    char b[200];
    std::snprintf(b, sizeof b,
                  "the %s sensor was at %.1f..%.1f degC, outside [limits] temp_min_c..temp_max_c = %.1f..%.1f degC",
                  names[s], static_cast<double>(lo), static_cast<double>(hi), limits.temp_min_c, limits.temp_max_c);
    flags.push_back({dsp::FlagCode::temperature, {}, b});
  }
  return flags;
}

// A run's frames as they are replayed, their temperatures seen on the way (a run of an
// earlier start, evaluated as it streams).
class WatchedFrames final : public dsp::FrameReplay {
 public:
  WatchedFrames(dsp::FrameReplay& frames, RecordingStats& stats) : frames_(frames), stats_(stats) {}
  void replay(const std::function<void(const dsp::Frame&)>& frame) override {
    const bool first = !seen_;
    seen_ = true;
    frames_.replay([&](const dsp::Frame& f) {
      if (first) stats_.add(f);
      frame(f);
    });
  }
  [[nodiscard]] std::size_t size_hint() const override { return frames_.size_hint(); }

 private:
  dsp::FrameReplay& frames_;
  RecordingStats& stats_;
  bool seen_ = false;
};

// How eicald analyses a run on disk: as it streams, a long one's evaluations spilled to the
// recording directory's disk (the samples' text reads slower than a spill reads back); one
// short enough to be evaluated whole (StreamOptions::materialize_samples) spills nothing.
dsp::StreamOptions stream_options(const std::filesystem::path& recording_dir, std::uint64_t frames) {
  dsp::StreamOptions so;
  so.spills = drivers::file_spills(recording_dir);
  so.spill_trace = so.spill_corrections = frames > so.materialize_samples;
  return so;
}

// The lag of the measured behind the recorded set-point and the alignment's residual.
void measure_alignment(const dsp::Run& run, dsp::SetPointOrigin& s) {
  std::vector<Eigen::Vector3d> cmd;
  cmd.reserve(run.frames.size());
  for (const auto& f : run.frames) cmd.emplace_back(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  const auto lag = dsp::align::estimate_lag(dsp::align::setpoint_accel_mps2(cmd, run.fs_hz()),
                                            dsp::align::measured_accel_mps2(run), run.fs_hz());
  s.lag_s = lag.lag_s, s.correlation = lag.correlation, s.residual_ratio = lag.residual_ratio;
}

// The uncertainty's draws on every core: the evaluation runs beside the measurement, not
// in its per-sample path (the acquisition and DSP threads hold their rings either way).
dsp::AnalysisOptions with_parallel_draws(dsp::AnalysisOptions o) {
  o.parallel = drivers::thread_for();
  return o;
}

}  // namespace

Evaluator::Evaluator(const DaemonConfig& config, dsp::RunMeta meta, dsp::AnalysisOptions analysis,
                     RecordingStream& stream, RecordingHandoff& handoff, EvaluatorLinks links)
    : config_(config),
      meta_(std::move(meta)),
      analysis_(with_parallel_draws(std::move(analysis))),
      handoff_(handoff),
      links_(std::move(links)),
      writer_(
          config.recording.dir, meta_, config.recording.gzip, stream,
          [this](const std::string& text, bool set) {
            if (set)
              set_fault(text);
            else
              clear_fault(text);
          },
          kWriteRetryS),
      thread_([this] { loop(); }) {}

Evaluator::~Evaluator() { finish(); }

void Evaluator::finish() {
  if (!thread_.joinable()) return;
  writer_.finish();  // the DSP thread has stopped: what it handed over is drained
  handoff_.quit();
  thread_.join();
}

EvaluationStatus Evaluator::status() const {
  std::lock_guard lk(mu_);
  return status_;
}

void Evaluator::set_fault(const std::string& fault) {
  std::lock_guard lk(mu_);
  status_.fault = fault;
}

void Evaluator::loop() {
  for (const auto& dir : links_.unevaluated) evaluate_recorded(dir);
  RecordedRun job;
  while (writer_.next(job)) {
    evaluate(job);
    if (job.handed_over) handoff_.done();  // the DSP thread may hand the next one over
    job = RecordedRun{};                   // its samples file closed
  }
}

dsp::Run Evaluator::make_run(const RecordedRun& job) const {
  dsp::Run run;
  run.meta = meta_;
  const std::string id = "eicald-" + utc_now("%Y%m%dT%H%M%SZ") + "-" + std::to_string(job.stats.first_index);
  run.meta.id = id;
  // The wall clock may step back (NTP, an operator) and a restarted source counts its
  // samples from 0 again: an id an earlier run has gets a suffix, it never replaces it.
  std::error_code ec;
  for (int n = 2; std::filesystem::exists(config_.recording.dir / run.meta.id, ec); ++n)
    run.meta.id = id + "-" + std::to_string(n);
  run.meta.created = utc_now();
  run.channels.psd_count = static_cast<int>(std::min<std::size_t>(meta_.psd.size(), dsp::kMaxPsd));
  return run;
}

std::optional<std::pair<int, dsp::Program>> Evaluator::named_program(const RecordingNotes& notes,
                                                                     std::vector<dsp::Flag>& flags) const {
  const auto& sp = config_.setpoint;
  const int number =
      std::isfinite(notes.program_p) ? static_cast<int>(std::lround(notes.program_p)) : sp.default_program;
  if (number < 0) {
    flags.push_back({dsp::FlagCode::setpoint,
                     {},
                     "M101 named no program (P word) and [setpoint.program] default_program is not set"});
    return std::nullopt;
  }
  try {
    return std::pair{number, drivers::ProgramCatalog(sp.program_dir).program(number)};
  } catch (const std::exception& e) {
    flags.push_back({dsp::FlagCode::setpoint, {}, "program " + std::to_string(number) + ": " + e.what()});
    return std::nullopt;
  }
}

std::vector<dsp::Flag> Evaluator::add_setpoint(dsp::Run& run, const RecordingNotes& notes) const {
  const auto& sp = config_.setpoint;
  std::vector<dsp::Flag> flags;
  if (sp.source == "none") return flags;
  const auto program = named_program(notes, flags);
  if (sp.source == "servo_stream") {
    // The set-point is LinuxCNC's; the program (when named) says what to evaluate.
    if (program) run.meta.program = program->second;
    dsp::SetPointOrigin s;
    s.source = "servo_stream";
    s.program_number = program ? program->first : -1;
    s.servo_rate_hz = sp.servo_rate_hz;
    const auto a = links_.servo ? links_.servo->alignment() : drivers::ServoAlignment{};
    if (a.known && !run.frames.empty())
      s.servo_cycle_at_first_sample =
          a.servo_cycle_at_sample0 +
          static_cast<double>(run.frames.front().sample_index - notes.index_offset) / run.fs_hz() * a.servo_rate_hz;
    measure_alignment(run, s);
    std::size_t missing = 0;
    for (const auto& f : run.frames) missing += (f.flags & dsp::frame_flag::cmd_missing) != 0;
    if (missing > 0)
      flags.push_back(
          {dsp::FlagCode::setpoint,
           {},
           std::to_string(missing) + " frames had no servo cycle of the set-point (LinuxCNC's stream absent or late)"});
    run.meta.setpoint = s;
    log(LogLevel::info,
        "setpoint: servo stream, cycle %.3f at the first sample; measured lags it by %+.2f ms, residual %s",
        s.servo_cycle_at_first_sample, s.lag_s * 1e3, percent(s.residual_ratio).c_str());
    return flags;
  }
  if (!program) return flags;
  try {
    drivers::ProgramSetPointOptions o;
    o.limits.a_max_mm_s2 = sp.a_max_mm_s2, o.limits.j_max_mm_s3 = sp.j_max_mm_s3,
    o.limits.rapid_mm_min = sp.rapid_mm_min;
    o.max_lag_s = sp.max_lag_s;
    o.mcode_stops = sp.mcode_stops;
    const drivers::ProgramAlignment a = drivers::apply_program_setpoint(run, program->second, o);
    dsp::SetPointOrigin s;
    s.source = "program";
    s.program_number = program->first;
    if (!a.blocks.empty()) {
      s.marks_offset_s = a.blocks.front().marks_offset_s, s.offset_s = a.blocks.front().offset_s;
      const auto [lo, hi] = std::minmax_element(a.blocks.begin(), a.blocks.end(),
                                                [](const auto& x, const auto& y) { return x.offset_s < y.offset_s; });
      s.block_offset_spread_s = hi->offset_s - lo->offset_s;
    }
    s.blocks = static_cast<int>(a.blocks.size());
    s.lag_s = a.lag_s, s.correlation = a.correlation, s.residual_ratio = a.residual_ratio;
    run.meta.setpoint = s;
    flags.insert(flags.end(), a.flags.begin(), a.flags.end());
    log(LogLevel::info,
        "setpoint: program %d aligned: marks %+.2f ms, cross-correlation %+.2f ms over %d block(s), residual %s",
        s.program_number, s.marks_offset_s * 1e3, (s.offset_s - s.marks_offset_s) * 1e3, s.blocks,
        percent(s.residual_ratio).c_str());
  } catch (const std::exception& e) {
    flags.push_back({dsp::FlagCode::setpoint, {}, "program " + std::to_string(program->first) + ": " + e.what()});
  }
  return flags;
}

std::vector<dsp::Flag> Evaluator::commit(RecordedRun& job, dsp::Run& run, const std::filesystem::path& dir) {
  std::vector<dsp::Flag> flags;
  if (config_.setpoint.source != "none") {
    // The set-point's alignment reads the whole recording: it comes back into memory here
    // (only with a set-point from elsewhere; the analysis streams).
    write_retrying("recording " + run.meta.id, [&] { job.run->finish_samples(); });
    dsp::Run full = job.run->load();
    full.meta = run.meta;
    flags = add_setpoint(full, job.notes);
    if (config_.setpoint.source == "program")
      write_retrying("recording " + run.meta.id, [&] { job.run->rewrite(full); });
    run.meta = std::move(full.meta);
  }
  // The run first: what was measured is durable before anything can fail.
  write_retrying("recording " + run.meta.id, [&] { job.run->commit(run.meta, dir); });
  return flags;
}

void Evaluator::add_service_flags(const RecordedRun& job, const dsp::Run& run,
                                  const std::vector<dsp::Flag>& setpoint_flags, dsp::Analysis& a) const {
  if (job.cause) a.flags.push_back(*job.cause), a.degraded = true;
  if (job.notes.nonfinite_frames > 0) {
    a.flags.push_back({dsp::FlagCode::not_finite,
                       {},
                       std::to_string(job.notes.nonfinite_frames) +
                           " frames had NaN/Inf in a temperature or set-point channel (last finite value held)"});
    a.degraded = true;
  }
  for (const auto& f : setpoint_flags) a.flags.push_back(f), a.degraded = true;
  if (job.notes.source_rate_ratio != 0.0) {
    char b[240];
    std::snprintf(b, sizeof b,
                  "the source delivered %.3g times the samples per second [acquisition] fs_hz = %.0f Hz "
                  "says during the measurement "
                  "(a DAQ at another rate, a replay faster than real time): its times, speeds and lengths are wrong",
                  job.notes.source_rate_ratio, run.fs_hz());
    a.flags.push_back({dsp::FlagCode::source_rate, {}, b}), a.degraded = true;
  }
  for (const auto& f : temperature_flags(run, job.stats, config_.limits)) a.flags.push_back(f), a.degraded = true;
  if (job.stats.lost > 0) {
    a.flags.push_back({dsp::FlagCode::recorder_overflow,
                       {},
                       std::to_string(job.stats.lost) +
                           " frames were not recorded (the recording thread fell behind by more than its ring holds)"});
    a.degraded = true;
  }
}

void Evaluator::evaluate(RecordedRun& job) {
  dsp::Run run = make_run(job);
  const auto dir = config_.recording.dir / run.meta.id;
  std::string error;
  try {
    const std::vector<dsp::Flag> setpoint_flags = commit(job, run, dir);
    // Streamed from disk as `eical analyze` reads a run: a recording of any length in
    // bounded memory (dsp/stream/analyze_stream.hpp).
    dsp::Analysis a;
    write_retrying("evaluation of " + run.meta.id, [&] {  // its spills on a full disk: again
      // The run directory removed meanwhile (an operator, a cleanup): made again from the
      // samples still open, first.
      if (!std::filesystem::exists(dir / "run.toml")) job.run->commit(run.meta, dir);
      try {
        drivers::RunStream frames(dir);
        a = dsp::analyze_stream(run, frames, analysis_, stream_options(config_.recording.dir, job.stats.frames));
      } catch (const dsp::InputError& e) {
        if (std::filesystem::exists(dir / "run.toml")) throw;
        throw std::runtime_error(e.what());  // it went while it was read: again
      }
    });
    add_service_flags(job, run, setpoint_flags, a);
    dsp::judge(run.meta.program, a);  // the verdict again, with the flags the daemon added
    write_retrying("result of " + run.meta.id, [&] {
      // The run directory removed meanwhile (an operator, a cleanup): made again from the
      // samples still open, first.
      if (!std::filesystem::exists(dir / "run.toml")) job.run->commit(run.meta, dir);
      drivers::write_result(run, a, dir / "result.json");
    });
    finish_result(run, a, dir);
    log(LogLevel::notice, "measurement %s written (%llu frames)%s", run.meta.id.c_str(),
        static_cast<unsigned long long>(job.stats.frames), a.degraded ? ", result degraded" : "");
  } catch (const std::exception& e) {
    error = e.what();
    log(LogLevel::error, "recording %s: %s", run.meta.id.c_str(), e.what());
  }
  if (!error.empty()) set_fault("recording: " + error);
}

void Evaluator::finish_result(const dsp::Run& run, const dsp::Analysis& a, const std::filesystem::path& dir) {
  if (links_.history) links_.history->append(run, a, dir);
  std::uint64_t number = 0;
  {
    // Counted before it is published: an HMI never sees a Result ahead of the count.
    std::lock_guard lk(mu_);
    number = ++status_.results;
    status_.last_result = (dir / "result.json").string();
  }
  publish(run, a, dir, number);
}

// The previous eicald stopped (kill -9, power, the watchdog) after the run was durable and
// before its result.json: evaluated now as `eical analyze` would, flagged, because what
// only the stopped DSP thread knew (a measurement cut short, non-finite channels held) is
// not in the run.
void Evaluator::evaluate_recorded(const std::filesystem::path& dir) {
  try {
    drivers::RunStream stream(dir);
    RecordingStats stats;
    WatchedFrames frames(stream, stats);
    const dsp::StreamOptions so = stream_options(config_.recording.dir, stream.size_hint());
    dsp::Analysis a = dsp::analyze_stream(stream.header(), frames, analysis_, so);
    if (!stream.presence_held())  // a sensor the first row did not show: again, as eical analyze does
      a = dsp::analyze_stream(stream.header(), frames, analysis_, so);
    const dsp::Run& run = stream.header();
    a.flags.push_back({dsp::FlagCode::evaluated_after_restart, {}, {}});
    a.degraded = true;
    for (const auto& f : temperature_flags(run, stats, config_.limits)) a.flags.push_back(f);
    dsp::judge(run.meta.program, a);
    write_retrying("result of " + run.meta.id, [&] { drivers::write_result(run, a, dir / "result.json"); });
    finish_result(run, a, dir);
    log(LogLevel::notice, "run %s of the previous start evaluated now (it had no result.json)", run.meta.id.c_str());
  } catch (const std::exception& e) {
    log(LogLevel::error, "run %s of the previous start: %s", dir.c_str(), e.what());
    set_fault("recording: " + dir.filename().string() + ": " + e.what());
  }
}

bool Evaluator::stopping() const { return handoff_.quitting() || (links_.stop && links_.stop->load()); }

// A disk that is full for a while, a recording directory removed or made unwritable:
// the measurement waits in memory and the write is tried again every kWriteRetryS (the DSP
// thread defers the next hand-over meanwhile, counted), so nothing measured is dropped for
// a fault that an operator clears. Status.fault says what is retried; it is cleared when
// the write succeeds. The service's stop ends the retries (the DSP thread then waits for
// the evaluator to hand over what the stop cut short): the last error is reported.
void Evaluator::write_retrying(const std::string& what, const std::function<void()>& write) {
  std::string fault;
  for (;;) {
    try {
      write();
      break;
    } catch (const dsp::InputError&) {
      throw;  // bad input: no retry makes it good
    } catch (const std::exception& e) {
      if (stopping()) throw;
      const std::string now = "recording: " + what + ": " + e.what() + "; retried every " +
                              std::to_string(static_cast<int>(kWriteRetryS)) + " s, the measurement is held in memory";
      if (now != fault) log(LogLevel::error, "%s", now.c_str());  // once per distinct cause, not per retry
      fault = now;
      set_fault(fault);
    }
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(kWriteRetryS);
    while (std::chrono::steady_clock::now() < until && !stopping())
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (fault.empty()) return;
  log(LogLevel::notice, "%s written after the fault cleared", what.c_str());
  clear_fault(fault);
}

void Evaluator::clear_fault(const std::string& fault) {
  std::lock_guard lk(mu_);
  if (status_.fault == fault) status_.fault.clear();
}

void Evaluator::publish(const dsp::Run& run, const dsp::Analysis& a, const std::filesystem::path& dir,
                        std::uint64_t result_number) {
  if (!links_.hmi) return;
  drivers::dds::ResultMsg r;
  r.machine = run.meta.machine.name;
  r.program_id = run.meta.id;
  r.measured_at = run.meta.created, r.run_path = dir.string(), r.software_version = drivers::software_version();
  r.sensor_calibration = links_.sensor_calibration;
  r.program = dsp::program_kind_name(run.meta.program.kind);
  r.degraded = a.degraded;
  r.results = result_number;
  if (a.circle)
    r.circular_deviation_G_um = a.circle->circular_deviation_G_um,
    r.radius_mean_deviation_um = a.circle->radius_mean_deviation_um;
  r.json = drivers::result_json(run, a).dump();
  links_.hmi->publish_result(r);
  if (auto t = make_trace(run, a, config_.dds.trace_max_points)) links_.hmi->publish_trace(*t);
}

}  // namespace eical::daemon
