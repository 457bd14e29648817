#include "dsp/stream/analyze_stream.hpp"

#include "dsp/analysis/channel_findings.hpp"
#include "dsp/analysis/figure_uncertainty.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_segments.hpp"
#include "dsp/eval/repeats.hpp"
#include "dsp/pipeline/integration_support.hpp"
#include "dsp/stream/circle_stream.hpp"
#include "dsp/stream/trace_spill.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>

namespace eical::dsp {
namespace {

constexpr std::size_t kTriggerCapacity = 4096;  // triggers the pipeline records (Pipeline::trigger_capacity_)

// The first pass's view of the trace: what the set-point alone decides — where a circle's
// evaluated stretches are, which segments repeat, whether the reference channel is whole.
class Scout final : public TraceSink {
 public:
  Scout(const Run& run, bool circle) : circle_(circle), repeats(std::vector<std::int64_t>{}) {
    const auto [ia, ib] = plane_axes(run.meta.program.plane);
    ia_ = ia, ib_ = ib;
    ref_finite = run.channels.ref[ia] && run.channels.ref[ib];
    if (!circle) return;
    try {
      segments.emplace(Eigen::Vector2d(run.meta.program.center_mm[0], run.meta.program.center_mm[1]),
                       run.meta.program.arc_deg);
    } catch (const InputError& e) {
      segment_error = std::string(e.what());
    }
  }
  // Every frame, before the pipeline: its M102 mark, as the pipeline records triggers.
  void frame(const Frame& f) {
    if (f.trigger == 0 || triggers_ >= kTriggerCapacity) return;
    ++triggers_;
    if (f.trigger != trigger::segment_mark || !circle_) return;
    repeats.mark(f.sample_index);
    marks_.push_back(f.sample_index);
  }
  void sample(const TraceSample& s) override {
    if (trace) trace->put(s);
    if (circle_) {
      repeats.add(n, s.sample_index, s.cmd_mm);
      // A mark counts at the trace sample it falls on (or, between samples, at the next
      // one); marks before the trace start nothing.
      bool mark = false;
      while (!marks_.empty() && marks_.front() <= s.sample_index) {
        mark = mark || n > 0 || marks_.front() == s.sample_index;
        marks_.pop_front();
      }
      if (segments) segments->add(s.sample_index, Eigen::Vector2d(s.cmd_mm[ia_], s.cmd_mm[ib_]), mark);
    }
    if (ref_finite) ref_finite = Eigen::Vector2d(s.ref_mm[ia_], s.ref_mm[ib_]).allFinite();
    ++n;
  }

  std::size_t n = 0;            // trace samples
  TraceSpill* trace = nullptr;  // the integrated trace, for the second pass
  bool circle_;
  eval::RepeatFinder repeats;
  std::optional<eval::CircleSegmentFinder> segments;
  std::optional<std::string> segment_error;
  bool ref_finite = false;

 private:
  int ia_ = 0, ib_ = 1;
  std::size_t triggers_ = 0;
  std::deque<std::int64_t> marks_;
};

// The smoothed errors as the smoother makes them, in a spill: the second pass reads each
// segment's instead of recomputing it (a filter pass forward and one back).
class CorrectionSpill final : public fusion::SegmentSink {
 public:
  explicit CorrectionSpill(SpillFactory factory) : factory_(std::move(factory)) {}
  void restart() override {
    spill_ = factory_();
    where_.clear();
    bytes_ = 0;
  }
  void segment(std::size_t j, const fusion::SmoothedSegment& s) override {
    if (where_.size() <= j) where_.resize(j + 1);
    where_[j] = {bytes_, s.first, s.size()};
    buf_.resize(s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
      for (int a = 0; a < 3; ++a)
        buf_[i].v[a] = s.dx_um[i][a], buf_[i].v[3 + a] = s.dv_um_s[i][a], buf_[i].v[6 + a] = s.sigma_x_um[i][a];
    spill_->write(buf_.data(), buf_.size() * sizeof(Doubles<9>));
    bytes_ += buf_.size() * sizeof(Doubles<9>);
  }
  [[nodiscard]] bool has(std::size_t j) const { return j < where_.size() && where_[j].size > 0; }
  [[nodiscard]] bool has_all(std::size_t segments) const {
    for (std::size_t j = 0; j < segments; ++j)
      if (!has(j)) return false;
    return true;
  }
  void load(std::size_t j, fusion::SmoothedSegment& out) {
    const Where& w = where_[j];
    buf_.resize(w.size);
    spill_->read_at(w.offset, buf_.data(), w.size * sizeof(Doubles<9>));
    out.first = w.first;
    out.dx_um.resize(w.size), out.dv_um_s.resize(w.size), out.sigma_x_um.resize(w.size);
    for (std::size_t i = 0; i < w.size; ++i)
      for (int a = 0; a < 3; ++a)
        out.dx_um[i][a] = buf_[i].v[a], out.dv_um_s[i][a] = buf_[i].v[3 + a], out.sigma_x_um[i][a] = buf_[i].v[6 + a];
  }

 private:
  struct Where {
    std::size_t offset = 0, first = 0, size = 0;
  };
  SpillFactory factory_;
  std::unique_ptr<Spill> spill_;
  std::vector<Where> where_;
  std::size_t bytes_ = 0;
  std::vector<Doubles<9>> buf_;
};

// A trace sample as the evaluation sees it: corrected by the supports, on the set-point's time.
struct Corrected {
  std::size_t k = 0;
  std::int64_t sample_index = 0;
  Eigen::Vector3d pos_mm, vel_mm_s, cmd_mm, ref_mm, sigma_um;
  float temp_c[2] = {0.0F, 0.0F};
  std::uint32_t frame_flags = 0;
};

// The second pass: the replayed integrated trace, the smoothed corrections applied segment
// by segment (SupportStage::finish), then re-indexed by the DAQ delay (Pipeline::align_delay).
class Emitter final : public TraceSink {
 public:
  Emitter(const Pipeline::Tracked& t, CorrectionSpill* kept, std::function<void(const Corrected&)> out)
      : n_(t.samples),
        apply_(t.correction && t.correction->apply),
        correction_(t.correction.get()),
        kept_(kept),
        d_(t.delay_samples),
        align_(t.delay_samples > 0.0 && t.samples >= 2),
        out_(std::move(out)) {}

  void sample(const TraceSample& s) override {
    Corrected c;
    c.k = seen_++;
    c.sample_index = s.sample_index;
    c.pos_mm = s.pos_mm, c.vel_mm_s = s.vel_mm_s, c.cmd_mm = s.cmd_mm, c.ref_mm = s.ref_mm;
    c.temp_c[0] = s.temp_c[0], c.temp_c[1] = s.temp_c[1], c.frame_flags = s.frame_flags;
    c.sigma_um = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (apply_) {
      if (c.k >= seg_.first + seg_.size() || !loaded_) {
        const std::size_t j = c.k / segment_samples_;
        if (kept_ && kept_->has(j))
          kept_->load(j, seg_);
        else
          correction_->smoother->segment(j, seg_);
        loaded_ = true;
      }
      const std::size_t i = c.k - seg_.first;
      c.pos_mm -= seg_.dx_um[i] / 1000.0;
      c.vel_mm_s -= seg_.dv_um_s[i] / 1000.0;
      c.sigma_um = seg_.sigma_x_um[i];
    }
    if (!align_) {
      out_(c);
      return;
    }
    src_.push_back({c.pos_mm, c.vel_mm_s});
    pending_.push_back(c);
    flush();
  }
  // Every segment's corrections are in the spill: the smoother and its track can go.
  [[nodiscard]] bool kept_whole() const {
    return !apply_ || (kept_ && kept_->has_all(correction_->smoother->segments()));
  }
  void forget_smoother() { correction_ = nullptr; }
  void finish() {
    if (seen_ != n_)
      throw InputError("the run changed between two readings (" + std::to_string(seen_) + " trace samples, then " +
                       std::to_string(n_) + ")");
    flush();
  }

 private:
  // Sample k of the trace holds what the sensors saw at k − d: k takes the value at k + d,
  // linear between samples; the last d samples hold the final value.
  void flush() {
    while (!pending_.empty()) {
      Corrected& c = pending_.front();
      const double src = static_cast<double>(c.k) + d_;
      const auto i = static_cast<std::size_t>(src);
      if (i + 1 >= n_) {
        if (seen_ < n_) return;  // the final value is not there yet
        c.pos_mm = src_.back().first, c.vel_mm_s = src_.back().second;
      } else {
        if (i + 1 >= seen_) return;
        const double f = src - static_cast<double>(i);
        const auto& x0 = src_[i - base_];
        const auto& x1 = src_[i + 1 - base_];
        c.pos_mm = (1.0 - f) * x0.first + f * x1.first;
        c.vel_mm_s = (1.0 - f) * x0.second + f * x1.second;
        while (base_ < i) src_.pop_front(), ++base_;  // later samples read from i on
      }
      out_(c);
      pending_.pop_front();
    }
  }

  std::size_t n_;
  bool apply_;
  const SmoothedCorrection* correction_;
  std::size_t segment_samples_ = apply_ ? correction_->smoother->segment_samples() : 0;
  CorrectionSpill* kept_;
  double d_;
  bool align_;
  std::function<void(const Corrected&)> out_;
  std::size_t seen_ = 0;
  fusion::SmoothedSegment seg_;
  bool loaded_ = false;
  std::deque<std::pair<Eigen::Vector3d, Eigen::Vector3d>> src_;  // corrected pos, vel from base_ on
  std::size_t base_ = 0;
  std::deque<Corrected> pending_;
};

// The schedule as the smoother used it, as the whole-trace pipeline keeps it for the
// uncertainty (Measurement::raw.schedule): ZUPT σ per sample again, CUPT as configured.
fusion::SupportSchedule schedule_as_fused(const SmoothedCorrection& c, const PipelineConfig& cfg) {
  fusion::SupportSchedule s = c.schedule;
  if (s.zupt_sigma_um_s.empty() && !c.track.zupt_unused.empty()) {
    s.zupt_sigma_um_s.resize(c.track.zupt_unused.size());
    for (std::size_t k = 0; k < s.zupt_sigma_um_s.size(); ++k)
      s.zupt_sigma_um_s[k] = c.track.zupt_unused[k] ? -1.0F : 0.0F;
  }
  s.cupt = cfg.cupt;
  return s;
}

// The per-sample arrays of the measurement: every sample, or every q-th and the last.
void keep(Measurement& m, const Corrected& c, std::size_t q, std::size_t n, const Eigen::Vector2d& temp) {
  if (c.k % q != 0 && c.k + 1 != n) return;
  m.temp_c.push_back(temp);
  m.sample_index.push_back(c.sample_index);
  m.pos_mm.push_back(c.pos_mm);
  m.vel_mm_s.push_back(c.vel_mm_s);
  m.cmd_mm.push_back(c.cmd_mm);
  m.ref_mm.push_back(c.ref_mm);
  m.sigma_um.push_back(c.sigma_um);
}

// What a run analysed as it streams must be: fs_hz positive, and no raw trace asked for.
void check_streamable(const Run& header, const AnalysisOptions& options) {
  if (!(header.meta.acquisition.fs_hz > 0.0)) throw InputError("run '" + header.meta.id + "': fs_hz must be positive");
  if (options.keep_raw)
    throw InputError("analysis: the raw trace (keep_raw) needs the whole run in memory (analyze_run)");
}

// What the first pass leaves for the second: the configuration, what the set-point decided,
// the spills, and the pipeline's track.
struct FirstPass {
  FirstPass(const Run& header, PipelineConfig config)
      : cfg(std::move(config)), scout(header, is_circle(header)), channel_check(header) {}
  static bool is_circle(const Run& header) { return header.meta.program.kind == ProgramKind::circle; }

  PipelineConfig cfg;
  Scout scout;
  health::ChannelHealth channel_check;  // each frame before the pipeline takes it
  std::optional<TraceSpill> trace_spill;
  std::optional<CorrectionSpill> kept;
  Pipeline::Tracked t;
};

// First pass: the pipeline keeping what the smoother reads; what the set-point decides.
void run_first_pass(const Run& header, FrameReplay& frames, const StreamOptions& stream, FirstPass& p) {
  if (stream.spill_trace)
    p.scout.trace = &p.trace_spill.emplace(stream.spills(),
                                           header.channels.ref[0] || header.channels.ref[1] || header.channels.ref[2]);
  p.cfg.trace = TraceKeeping::track;
  p.cfg.sink = &p.scout;
  std::size_t n_frames = 0;
  if (stream.spill_corrections) p.kept.emplace(stream.spills);
  {
    Pipeline pipeline(p.cfg);
    Scout& scout = p.scout;
    health::ChannelHealth& check = p.channel_check;
    frames.replay([&scout, &check, &pipeline, &n_frames](const Frame& f) {
      check.frame(f);
      scout.frame(f);
      pipeline.step(f);
      ++n_frames;
    });
    if (n_frames == 0) throw InputError("run '" + header.meta.id + "' holds no frames");
    p.t = pipeline.finish_track(p.kept ? &*p.kept : nullptr);
  }
  p.scout.repeats.finish();
}

// The analysis as the first pass's track has it: the measurement without its per-sample arrays.
Analysis analysis_of_track(const PipelineConfig& cfg, const AnalysisOptions& options, Pipeline::Tracked& t) {
  Analysis a;
  a.dynamic = cfg.dynamic, a.nbs = cfg.nbs, a.coriolis = cfg.coriolis;
  a.sensor_model = options.sensor_model;
  a.measurement = std::move(t.measurement);
  a.measurement.trace_samples = t.samples;
  a.flags = a.measurement.flags;
  a.degraded = a.measurement.degraded;
  return a;
}

// What takes each corrected sample of the second pass: the measurement's arrays (every
// q-th sample), and for a circle evaluated as it streams, its evaluations.
struct SecondPass {
  SecondPass(const Run& header, Measurement& measurement, std::size_t samples, bool whole_trace, std::size_t every)
      : n(samples),
        whole(whole_trace),
        q(every),
        m(measurement),
        temp(header.meta.sensors[0].temp_ref_c, header.meta.sensors[1].temp_ref_c) {}
  void sample(const Corrected& c);

  std::size_t n;  // trace samples
  bool whole;     // the whole trace kept, evaluated as analyze_run() does
  std::size_t q;  // decimation of the per-sample arrays
  Measurement& m;
  Eigen::Vector2d temp;  // the last finite case temperatures
  std::optional<CircleStream> circle_eval;
  std::optional<eval::RepeatAverager> repeats;
  std::optional<UncertaintyTrace> uncertainty;
};

void SecondPass::sample(const Corrected& c) {
  for (int i = 0; i < 2; ++i)
    if (!(c.frame_flags & frame_flag::temp_missing) && std::isfinite(c.temp_c[i]))
      temp[i] = static_cast<double>(c.temp_c[i]);
  keep(m, c, q, n, temp);
  if (c.sigma_um.allFinite()) m.sigma_max_um = m.sigma_max_um.cwiseMax(c.sigma_um);
  m.sigma_peak_um = std::max(m.sigma_peak_um, c.sigma_um.maxCoeff());
  if (circle_eval) circle_eval->sample(c.sample_index, c.pos_mm, c.cmd_mm, c.ref_mm);
  if (repeats) repeats->add(c.k, c.pos_mm, c.cmd_mm);
  if (uncertainty) uncertainty->sample(c.k, c.sample_index, c.pos_mm, c.vel_mm_s, c.cmd_mm, c.ref_mm, temp);
}

// A run short enough keeps its whole trace and is evaluated as analyze_run() does; a
// longer circle is evaluated as it streams.
bool keeps_whole_trace(const Run& header, std::size_t n, const StreamOptions& stream) {
  return !FirstPass::is_circle(header) || n <= stream.materialize_samples;
}

// The decimation of the per-sample arrays: none for a whole trace, else about
// measurement_points of them.
std::size_t decimation(bool whole, std::size_t n, const StreamOptions& stream) {
  return whole ? 1
               : std::max<std::size_t>(
                     1, (n + stream.measurement_points - 1) / std::max<std::size_t>(1, stream.measurement_points));
}

// The evaluations of a circle evaluated as it streams, from what the first pass decided;
// the uncertainty reads what it needs of the trace as it goes by (figure_uncertainty.hpp).
void start_streamed_evaluation(const Run& header, const AnalysisOptions& options, const StreamOptions& stream,
                               const FirstPass& p, const Analysis& a, SecondPass& s) {
  if (s.whole) return;
  const Scout& scout = p.scout;
  s.circle_eval.emplace(header, scout.segments ? scout.segments->segments() : std::vector<eval::CircleSegment>{},
                        scout.segment_error, scout.ref_finite, stream.spills);
  s.repeats.emplace(scout.repeats.groups(), stream.spills(), stream.measurement_points);
  if (options.uncertainty.enabled && p.t.correction) {
    const SmoothedCorrection* c = p.t.correction.get();
    const std::int64_t first = p.t.first_index;
    s.uncertainty.emplace(
        header, p.cfg, options, a, c->schedule, s.n, [c, first](std::size_t k) { return c->sample_index_of(first, k); },
        &c->track.zupt_unused);
  }
}

// Second pass: the corrected trace, each sample to s as it goes by — from the trace spill,
// or the frames through the pipeline again (the same numbers: the same code).
void run_second_pass(const Run& header, FrameReplay& frames, FirstPass& p, SecondPass& s) {
  p.scout = Scout(header, false);  // what it decided is out; its set-point records can go
  p.scout.trace = nullptr;
  Emitter emitter(p.t, p.kept ? &*p.kept : nullptr, [&s](const Corrected& c) { s.sample(c); });
  // A long run's corrections all kept, its track (a byte and a bit per sample) and the
  // smoother's checkpoints go before the second pass: the uncertainty has coarsened what it
  // reads of the schedule, the emitter reads the spill.
  if (!s.whole && emitter.kept_whole()) {
    emitter.forget_smoother();
    p.t.correction.reset();
  }
  if (p.trace_spill) {  // the integrated trace as the first pass saw it
    p.trace_spill->replay([&emitter](const TraceSample& ts) { emitter.sample(ts); });
    p.trace_spill.reset();
  } else {
    PipelineConfig cfg2 = p.cfg;
    cfg2.trace = TraceKeeping::replay;
    cfg2.sink = &emitter;
    Pipeline replay(cfg2);
    frames.replay([&replay](const Frame& f) { replay.step(f); });
  }
  emitter.finish();
  p.t.correction.reset();  // the smoother's records: done
}

// The streamed evaluations' figures into the analysis; false, with every positional figure
// null, when the integration is not supported (run-format.md, "No standstill";
// evaluate_measurement()).
bool finish_streamed_figures(SecondPass& s, Analysis& a) {
  if (const std::string why = unsupported_integration(s.m); !why.empty()) {
    a.flags.push_back({FlagCode::position_unsupported, {}, why});
    a.degraded = true;
    return false;
  }
  s.circle_eval->finish(a);
  s.circle_eval.reset();
  a.repeats = s.repeats->result();
  return true;
}

// Their uncertainty, after the figures.
void finish_streamed_uncertainty(const Run& header, const AnalysisOptions& options, SecondPass& s, Analysis& a) {
  if (s.uncertainty)
    s.uncertainty->finish(header, a);
  else if (options.uncertainty.enabled)
    a.uncertainty_note = "no support schedule: the uncertainty was not estimated";
}

}  // namespace

Analysis analyze_stream(const Run& header, FrameReplay& frames, const AnalysisOptions& options,
                        const StreamOptions& stream) {
  check_streamable(header, options);
  PipelineConfig cfg = analysis_config(header.meta, std::numeric_limits<std::size_t>::max(), options);
  cfg.reserve_samples = frames.size_hint();
  FirstPass first(header, std::move(cfg));
  run_first_pass(header, frames, stream, first);
  Analysis a = analysis_of_track(first.cfg, options, first.t);
  // No figures — a channel the program needs measures nothing, or nothing moved — and no
  // second pass: a verdict all the same.
  if (!judge_channels(header.meta, first.channel_check.finish(), a) || first.t.samples == 0) {
    judge(header.meta.program, a);
    return a;
  }

  // A circle is evaluated in the second pass; other programs keep the whole trace for theirs.
  const std::size_t n = first.t.samples;
  const bool whole = keeps_whole_trace(header, n, stream);
  if (whole && options.uncertainty.enabled && first.t.correction)
    a.measurement.raw.schedule = schedule_as_fused(*first.t.correction, first.cfg);
  const std::size_t q = decimation(whole, n, stream);
  a.measurement.decimation = q;
  SecondPass second(header, a.measurement, n, whole, q);
  start_streamed_evaluation(header, options, stream, first, a, second);
  // The second pass and the streamed figures (one core) beside the uncertainty's
  // integration noise, which reads the coarse schedule only (figure_uncertainty.hpp); the
  // noise's draws are taken one by one, by both tasks once the first is done.
  bool supported = true;
  const ParallelFor parallel = options.parallel ? options.parallel : sequential_for();
  parallel(2, [&](std::size_t task) {
    if (task == 0) {
      run_second_pass(header, frames, first, second);
      if (!whole) supported = finish_streamed_figures(second, a);
    }
    if (second.uncertainty) second.uncertainty->draw_noise();  // task 0 joins in when done
  });

  if (whole) {
    evaluate_measurement(header, first.cfg, options, a);  // as analyze_run(): the whole trace is here
    return a;
  }
  if (supported) finish_streamed_uncertainty(header, options, second, a);
  judge(header.meta.program, a);
  return a;
}

}  // namespace eical::dsp
