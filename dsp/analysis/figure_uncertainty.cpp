#include "dsp/analysis/figure_uncertainty.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/index_span.hpp"
#include "dsp/core/stream_seed.hpp"
#include "dsp/uncertainty/error_field.hpp"
#include "dsp/uncertainty/rest_noise_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <utility>

namespace eical::dsp {
namespace {

// Draws evaluate the path at about this rate (the error is smooth; the figures need no more).
constexpr double kDrawRateHz = 1000.0;
constexpr std::size_t kMaxDrawSamples = 30000;
// Tasks the draws are split into (each copies the bases' measurement once).
constexpr std::size_t kDrawBlocks = 8;

// The paths the draws perturb, evaluated at the draws' rate, on one set-point:
//   * the truth's estimate t̂ = s + λ (m − s): the measured path m shrunk towards the
//     set-point s by as much of its shape as the error itself explains. m − s is the
//     machine's shape plus the measurement's error e; their energies add, so
//     λ² = 1 − max‖e‖² / ‖m − s‖² (the largest of 20 draws, clamped to 0..1). On a
//     machine whose shape is all noise λ = 0 and t̂ is the set-point; on one whose shape
//     towers over the noise λ = 1 and t̂ is the measured path. A figure's error is then
//     drawn where the truth most likely is: a range such as G is biased by the noise by as
//     much as the true shape leaves room for (at most f(e), on a flat path), a linear
//     figure is the same on any path;
//   * the set-point s with the noise bound's error (white noise only, optimal smoother).
struct DrawBases {
  std::unique_ptr<SetPointCache> setpoint;  // every evaluation's: one set-point
  EvaluationOptions eo;
  Analysis truth, ideal;            // t̂ and s
  std::vector<FigureValue> t0, g0;  // their figures
  std::vector<double> at;           // the trace positions the draws perturb
  double shrink = 1.0;              // λ
  MoreFigures more;                 // the caller's figures beside the program's
};

// The program's figures and the caller's (AnalysisOptions::more_figures).
std::vector<FigureValue> all_figures(const Analysis& a, const MoreFigures& more) {
  std::vector<FigureValue> f = figures_of(a);
  if (more)
    for (FigureValue& v : more(a)) f.push_back(std::move(v));
  return f;
}

// The decimated measurement (every q-th sample of the trace: fs/q; the triggers kept) with
// its positions replaced.
Analysis base_of(const Analysis& a, const Measurement& decimated, std::vector<Eigen::Vector3d> pos_mm) {
  Analysis b;
  b.measurement = decimated;
  b.measurement.pos_mm = std::move(pos_mm);
  b.dynamic = a.dynamic, b.nbs = a.nbs;
  return b;
}

// The positions of `m` the figures read, or empty: all of them. A positioning test reads
// the dwells only; the servo's lag while it moves is shape no figure sees, and taken as
// shape it made λ ≈ 0.5 on flat machines (4 of 40 data-sheet runs then had U(M) below
// their error).
std::vector<IndexSpan> read_spans(const Analysis& a, const Measurement& m) {
  std::vector<IndexSpan> spans;
  if (a.positioning_input)
    for (const auto& [first, last] : a.positioning_input->read_sample_index)
      spans.push_back(index_span(m.sample_index, first, last + 1));
  return spans;
}

// λ of the truth's estimate from the measured path's shape and the energy of `errors` over
// the positions the figures read: the largest of the draws', not their mean. Only the
// shape that no plausible error explains is kept as the machine's (a run whose sensor model
// errs at the far end of its tolerances must not lend that error to the machine, where the
// draws would take it as shape and shrink its bias: seen as G covered in one of three
// data-sheet circles).
double shrink_factor(const Measurement& m, const std::vector<std::vector<Eigen::Vector3d>>& errors,
                     std::vector<IndexSpan> spans) {
  if (spans.empty()) spans.push_back({0, m.pos_mm.size()});
  double shape_um2 = 0.0, error_um2 = 0.0;
  for (const IndexSpan& s : spans)
    for (std::size_t k = s.begin; k < s.end && k < m.pos_mm.size(); ++k)
      shape_um2 += ((m.pos_mm[k] - m.cmd_mm[k]) * 1000.0).squaredNorm();
  for (const auto& e : errors) {
    double energy_um2 = 0.0;
    for (const IndexSpan& s : spans)
      for (std::size_t k = s.begin; k < s.end && k < e.size(); ++k) energy_um2 += e[k].squaredNorm();
    error_um2 = std::max(error_um2, energy_um2);
  }
  if (errors.empty() || !(shape_um2 > 0.0)) return 0.0;
  return std::sqrt(std::clamp(1.0 - error_um2 / shape_um2, 0.0, 1.0));
}

// Draws that measure λ, seeded apart from the draws proper: the largest energy of 20 is
// about its 95th percentile.
constexpr std::uint64_t kShrinkSalt = 0x736872696e6bULL;
constexpr int kShrinkDraws = 20;

DrawBases evaluate_bases(const Run& run, const Analysis& a, const uncertainty::ErrorField& field, Measurement decimated,
                         std::size_t q, std::size_t samples, std::uint64_t seed, MoreFigures more) {
  const Measurement& m = a.measurement;
  DrawBases b;
  b.more = std::move(more);
  b.eo.reference = false;
  b.eo.keep_trace = false;
  if (a.diagnostics) b.eo.cyclic_pitch_mm = a.diagnostics->cyclic_pitch_mm;
  decimated.fs_hz = m.fs_hz / static_cast<double>(q);
  decimated.triggers = m.triggers;
  decimated.start_index = m.start_index, decimated.motion_end_index = m.motion_end_index;
  for (std::size_t i = 0; i < samples; i += q) b.at.push_back(static_cast<double>(i));
  std::vector<std::vector<Eigen::Vector3d>> errors(kShrinkDraws);
  for (int d = 0; d < kShrinkDraws; ++d) {
    std::mt19937_64 rng(stream_seed(seed ^ kShrinkSalt, static_cast<std::uint64_t>(d)));
    field.draw(rng, b.at, errors[static_cast<std::size_t>(d)]);
  }
  b.shrink = shrink_factor(decimated, errors, read_spans(a, decimated));
  std::vector<Eigen::Vector3d> shrunk(decimated.pos_mm.size());
  for (std::size_t k = 0; k < shrunk.size(); ++k)
    shrunk[k] = decimated.cmd_mm[k] + b.shrink * (decimated.pos_mm[k] - decimated.cmd_mm[k]);
  b.ideal = base_of(a, decimated, decimated.cmd_mm);
  b.truth = base_of(a, decimated, std::move(shrunk));
  b.setpoint = std::make_unique<SetPointCache>();
  b.eo.setpoint = b.setpoint.get();
  evaluate_program(run, b.truth, b.eo);  // fills the set-point cache
  evaluate_program(run, b.ideal, b.eo);
  b.setpoint->frozen = true;  // the draws read it in parallel
  b.t0 = all_figures(b.truth, b.more), b.g0 = all_figures(b.ideal, b.more);
  return b;
}

// The figures of a base with a draw's error (µm) added to its path. The draw perturbs the
// positions of `scratch` only: the rest of the base's measurement is copied into it once
// (the evaluation reads it, never writes it), not per draw (200 copies of every array, each
// mapped and faulted in afresh).
std::vector<FigureValue> perturbed_figures(const Run& run, const Analysis& a, const Analysis& base,
                                           const std::vector<Eigen::Vector3d>& err, const DrawBases& b,
                                           Measurement& scratch) {
  Analysis x;
  x.measurement = std::move(scratch);
  x.measurement.pos_mm.assign(base.measurement.pos_mm.begin(), base.measurement.pos_mm.end());
  for (std::size_t i = 0; i < err.size() && i < x.measurement.pos_mm.size(); ++i)
    x.measurement.pos_mm[i] += err[i] / 1000.0;
  x.dynamic = a.dynamic, x.nbs = a.nbs;
  evaluate_program(run, x, b.eo);
  std::vector<FigureValue> f = all_figures(x, b.more);
  scratch = std::move(x.measurement);
  return f;
}

struct DrawnFigures {
  std::vector<FigureValue> error;  // t̂ with the draw's error
  std::vector<FigureValue> noise;  // s with the noise bound's error only
};

// The noise bound's draws are seeded apart from the error field's (the same draw numbers).
constexpr std::uint64_t kNoiseBoundSalt = 0x6e6f697365626e64ULL;

// The seeded draws [from, to): the error field's on t̂, the noise bound's on s, each
// evaluated. Contiguous blocks of draws are the executor's tasks (one copy of the bases'
// measurement a block).
void draw_range(const Run& run, const Analysis& a, const uncertainty::ErrorField& field, const DrawBases& b,
                std::size_t from, std::size_t to, std::uint64_t seed, const ParallelFor& parallel,
                std::vector<std::optional<uncertainty::NoiseDraw>>& noise, std::vector<DrawnFigures>& drawn) {
  const std::size_t n = to - from;
  const std::size_t blocks = std::min<std::size_t>(n, kDrawBlocks);
  parallel(blocks, [&](std::size_t block) {
    std::vector<Eigen::Vector3d> err;
    Measurement truth_scratch = b.truth.measurement, ideal_scratch = b.ideal.measurement;
    for (std::size_t d = from + block * n / blocks; d < from + (block + 1) * n / blocks; ++d) {
      // Seeded by (seed, d) alone, so the draws may run in any order and on any thread.
      if (d < noise.size() && noise[d]) {  // its noise drawn already, from the same generator
        field.draw(std::move(*noise[d]), b.at, err);
      } else {
        std::mt19937_64 rng(stream_seed(seed, d));
        field.draw(rng, b.at, err);
      }
      drawn[d].error = perturbed_figures(run, a, b.truth, err, b, truth_scratch);
      std::mt19937_64 bound_rng(stream_seed(seed ^ kNoiseBoundSalt, d));
      field.draw_bound(bound_rng, b.at, err);
      drawn[d].noise = perturbed_figures(run, a, b.ideal, err, b, ideal_scratch);
    }
  });
}

// The 95th percentile of |x| (linear interpolation between order statistics); NaN when
// fewer than half the draws gave a finite value.
double abs_quantile95(std::vector<double>& x, std::size_t draws) {
  if (x.empty() || 2 * x.size() < draws) return std::numeric_limits<double>::quiet_NaN();
  for (double& v : x) v = std::abs(v);
  std::sort(x.begin(), x.end());
  const double pos = 0.95 * static_cast<double>(x.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return i + 1 < x.size() ? (1.0 - f) * x[i] + f * x[i + 1] : x[i];
}

// Per element of figure `key` (`elements` values), the 95th percentile of its error over
// the first `used` draws of `which` against its base's value; empty when the base lacks it
// in that shape.
std::vector<double> quantile_of_figure(const std::vector<FigureValue>& base, const std::vector<DrawnFigures>& drawn,
                                       std::size_t used, std::vector<FigureValue> DrawnFigures::*which,
                                       const std::string& key, std::size_t elements) {
  const FigureValue* b = find_figure(base, key);
  if (!b || b->values.size() != elements) return {};
  std::vector<double> out(elements);
  std::vector<double> dev;
  for (std::size_t e = 0; e < elements; ++e) {
    dev.clear();
    for (std::size_t d = 0; d < used; ++d) {
      const FigureValue* v = find_figure(drawn[d].*which, key);
      if (v && v->values.size() == elements && std::isfinite(v->values[e] - b->values[e]))
        dev.push_back(v->values[e] - b->values[e]);
    }
    out[e] = abs_quantile95(dev, used);
  }
  return out;
}

// U and the noise bound of every figure of the full-rate analysis, from the draws.
void assign_uncertainties(const DrawBases& b, const std::vector<DrawnFigures>& drawn, std::size_t used, Analysis& a) {
  for (const FigureValue& full : all_figures(a, b.more)) {
    if (a.not_evaluated.count(full.key)) continue;  // the evaluation's own reason stands
    std::vector<double> u = quantile_of_figure(b.t0, drawn, used, &DrawnFigures::error, full.key, full.values.size());
    if (!u.empty()) {
      if (u.size() == 1 && u[0] == 0.0)  // no draw moves it: not a measured size
        a.not_evaluated[full.key] =
            "every Monte Carlo draw of the measurement's error gives the same value: it does not follow the "
            "measurement";
      else
        a.uncertainty_k2[full.key] = std::move(u);
    }
    std::vector<double> bound =
        quantile_of_figure(b.g0, drawn, used, &DrawnFigures::noise, full.key, full.values.size());
    if (!bound.empty()) a.noise_bound_k2[full.key] = std::move(bound);
  }
}

// The budget: per source, `draws` draws of that source alone on t̂ (seeded apart), and the
// 95th percentile of every figure's error over them.
void assign_budget(const Run& run, const Analysis& a_in, const uncertainty::ErrorField& field, const DrawBases& b,
                   int draws, std::uint64_t seed, const ParallelFor& parallel, Analysis& a) {
  const auto n = static_cast<std::size_t>(draws);
  const std::vector<FigureValue> figs = all_figures(a, b.more);
  for (const uncertainty::ErrorSource source : uncertainty::kErrorSources) {
    std::vector<DrawnFigures> drawn(n);
    const std::uint64_t salt = 0x627564676574ULL + static_cast<std::uint64_t>(source);
    const std::size_t blocks = std::min<std::size_t>(n, kDrawBlocks);
    parallel(blocks, [&](std::size_t block) {
      std::vector<Eigen::Vector3d> err;
      Measurement scratch = b.truth.measurement;
      for (std::size_t d = block * n / blocks; d < (block + 1) * n / blocks; ++d) {
        std::mt19937_64 rng(stream_seed(seed ^ salt, d));
        field.draw(rng, b.at, err, uncertainty::SourceMask::only(source));
        drawn[d].error = perturbed_figures(run, a_in, b.truth, err, b, scratch);
      }
    });
    auto& by_key = a.uncertainty_budget[source];
    for (const FigureValue& f : figs) {
      std::vector<double> u = quantile_of_figure(b.t0, drawn, n, &DrawnFigures::error, f.key, f.values.size());
      if (!u.empty()) by_key[f.key] = std::move(u);
    }
  }
}

// The draws that ran: all of them, or the screen's first ones when they already put U of
// its figure above its bound.
std::size_t run_draws(const Run& run, const Analysis& a, const uncertainty::ErrorField& field, const DrawBases& b,
                      int draws, std::uint64_t seed, const ParallelFor& parallel,
                      const std::optional<AnalysisOptions::Uncertainty::StopAbove>& stop,
                      std::vector<std::optional<uncertainty::NoiseDraw>>& noise, std::vector<DrawnFigures>& drawn) {
  const auto n = static_cast<std::size_t>(draws);
  drawn.assign(n, {});
  const std::size_t first = stop ? static_cast<std::size_t>(std::clamp(stop->after_draws, 2, draws)) : n;
  draw_range(run, a, field, b, 0, first, seed, parallel, noise, drawn);
  if (first < n) {
    const std::vector<double> u = quantile_of_figure(b.t0, drawn, first, &DrawnFigures::error, stop->key, 1);
    if (u.size() == 1 && u[0] > stop->above) return first;
    draw_range(run, a, field, b, first, n, seed, parallel, noise, drawn);
  }
  return n;
}

}  // namespace

void estimate_uncertainty(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, Analysis& a) {
  const Measurement& m = a.measurement;
  const auto& fine = m.raw.schedule;
  if (fine.flags.empty() || m.sample_index.size() < 2) {
    a.uncertainty_note = "no support schedule: the uncertainty was not estimated";
    return;
  }
  const std::size_t n = std::min({m.sample_index.size(), m.pos_mm.size(), m.cmd_mm.size()});
  UncertaintyTrace trace(run, config, options, a, fine, n, [&m](std::size_t k) { return m.sample_index[k]; });
  // The case temperatures along the trace (α_b's effect): a streamed run's, else from the frames.
  const bool streamed_temp = m.temp_c.size() == m.sample_index.size();
  std::size_t f = 0;
  Eigen::Vector2d last(run.meta.sensors[0].temp_ref_c, run.meta.sensors[1].temp_ref_c);
  for (std::size_t k = 0; k < n; ++k) {
    if (streamed_temp) {
      last = m.temp_c[k];
    } else {
      while (f < run.frames.size() && run.frames[f].sample_index < m.sample_index[k]) ++f;
      if (f < run.frames.size()) {
        const Frame& fr = run.frames[f];
        for (int s = 0; s < 2; ++s)
          if (!(fr.flags & frame_flag::temp_missing) && std::isfinite(fr.temp_c[s]))
            last[s] = static_cast<double>(fr.temp_c[s]);
      }
    }
    trace.sample(k, m.sample_index[k], m.pos_mm[k], k < m.vel_mm_s.size() ? m.vel_mm_s[k] : Eigen::Vector3d::Zero(),
                 m.cmd_mm[k], k < m.ref_mm.size() ? m.ref_mm[k] : Eigen::Vector3d::Constant(kNaN), last);
  }
  trace.finish(run, a);
}

UncertaintyTrace::UncertaintyTrace(const Run& run, const PipelineConfig& config, const AnalysisOptions& options,
                                   const Analysis& a, const fusion::SupportSchedule& schedule, std::size_t samples,
                                   std::function<std::int64_t(std::size_t)> index_at,
                                   const std::vector<bool>* zupt_unused)
    : samples_(samples),
      draws_(std::max(2, options.uncertainty.draws)),
      stop_above_(options.uncertainty.stop_above),
      budget_draws_(options.uncertainty.budget ? std::max(2, options.uncertainty.budget_draws) : 0),
      seed_(options.uncertainty.seed),
      more_(options.more_figures),
      parallel_(options.parallel ? options.parallel : sequential_for()) {
  const Measurement& m = a.measurement;
  uncertainty::ErrorFieldInput& in = in_;
  in.fs_hz = m.fs_hz;
  in.delay_samples = a.dynamic == DynamicComp::none ? 0.0 : config.acquisition.daq_group_delay_samples;
  in.model = config.fusion;
  in.model.start_frame_um = m.supports.start_frame_um;    // as the pipeline anchored the start
  in.model.scale_state_ppm = m.supports.scale_state_ppm;  // and kept the scale
  in.model.timing_state_us = m.supports.timing_state_us;  // and the timing
  if (m.supports.bias_step_um_s2 > 0.0) in.model.bias_step_um_s2 = m.supports.bias_step_um_s2;  // as it measured
  in.start_bias_sigma_um_s2 = m.supports.start_bias_sigma_um_s2;
  in.model_covariance =
      options.model_covariance ? *options.model_covariance : dsp::datasheet_covariance(run.meta.sensors, m.fs_hz);
  in.sensor_noise_ug_per_rthz[0] = run.meta.sensors[0].noise_ug_per_rthz;
  in.sensor_noise_ug_per_rthz[1] = run.meta.sensors[1].noise_ug_per_rthz;
  for (int s = 0; s < 2; ++s)
    in.bias_walk_ug_per_rts[s] = run.meta.sensor_present[s] ? run.meta.sensors[s].bias_walk_ug_per_rts : 0.0;
  in.g_mps2 = run.meta.site.g_mps2;
  for (int j = 0; j < 3; ++j) in.owner[static_cast<std::size_t>(j)] = axis_owner(run.meta.machine, j);
  in.psd = run.meta.psd;
  if (m.rest_noise.measured())  // the axes' rms: the fusion's model is one density for all
    in.rel_noise_ug_per_rthz = std::sqrt(m.rest_noise.density_ug_rthz.squaredNorm() / 3.0);

  // The schedule as the trace was actually fused: without the strips when they disagreed,
  // without any support when the fusion diverged (the trace stayed as integrated).
  uncertainty::FineSchedule fine;
  fine.schedule = &schedule;
  fine.samples = std::min(samples, schedule.flags.size());
  fine.index_at = std::move(index_at);
  fine.zupt_unused = zupt_unused;
  fine.fs_hz = m.fs_hz;
  if (m.supports.diverged) fine.flag_mask = fusion::schedule_flag::move_start | fusion::schedule_flag::invalid;
  uncertainty::CoarseSchedule& c = coarse_.emplace(
      uncertainty::coarsen(fine, in.model, uncertainty::ErrorField::block_for(fine.samples, in.max_coarse)));
  if (m.supports.psd_disagrees) c.schedule.cupt = false;
  if (m.supports.diverged) c.schedule.zupt = c.schedule.cupt = false;
  probe_.emplace(c, in.delay_samples, samples, in.fs_hz);

  // Slots for the noise draw_noise() may draw before finish(): the screen's first draws only
  // when a screen may end the draws there.
  noise_.resize(static_cast<std::size_t>(stop_above_ ? std::clamp(stop_above_->after_draws, 2, draws_) : draws_));
  // The draws evaluate the path at about kDrawRateHz, at most kMaxDrawSamples of it.
  q_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(m.fs_hz / kDrawRateHz)));
  q_ = std::max(q_, (samples + kMaxDrawSamples - 1) / kMaxDrawSamples);
  const std::size_t kept = (samples + q_ - 1) / q_;
  nominal_.sample_index.reserve(kept), nominal_.pos_mm.reserve(kept), nominal_.vel_mm_s.reserve(kept);
  nominal_.cmd_mm.reserve(kept), nominal_.ref_mm.reserve(kept);
}

void UncertaintyTrace::draw_noise() {
  for (std::size_t d = next_noise_++; d < noise_.size(); d = next_noise_++)
    noise_[d] = uncertainty::draw_noise(in_, *coarse_, std::mt19937_64(stream_seed(seed_, d)));
}

void UncertaintyTrace::sample(std::size_t k, std::int64_t sample_index, const Eigen::Vector3d& pos_mm,
                              const Eigen::Vector3d& vel_mm_s, const Eigen::Vector3d& cmd_mm,
                              const Eigen::Vector3d& ref_mm, const Eigen::Vector2d& temp_c) {
  probe_->sample(k, pos_mm, vel_mm_s, temp_c);
  if (k % q_ != 0 || k >= samples_) return;
  nominal_.sample_index.push_back(sample_index);
  nominal_.pos_mm.push_back(pos_mm);
  nominal_.vel_mm_s.push_back(vel_mm_s);
  nominal_.cmd_mm.push_back(cmd_mm);
  nominal_.ref_mm.push_back(ref_mm);
}

void UncertaintyTrace::finish(const Run& run, Analysis& a) {
  a.uncertainty_source = in_.model_covariance.source;
  std::unique_ptr<uncertainty::ErrorField> field;
  try {
    const uncertainty::CoarsePath path = probe_->path(true);
    probe_.reset();
    field = std::make_unique<uncertainty::ErrorField>(in_, std::move(*coarse_), path);
    coarse_.reset();
  } catch (const InputError& e) {
    a.uncertainty_note = std::string("the uncertainty was not estimated: ") + e.what();
    return;
  }
  const DrawBases bases =
      evaluate_bases(run, a, *field, std::exchange(nominal_, Measurement{}), q_, samples_, seed_, more_);
  std::vector<DrawnFigures> drawn;
  const std::size_t used = run_draws(run, a, *field, bases, draws_, seed_, parallel_, stop_above_, noise_, drawn);
  noise_.clear();
  assign_uncertainties(bases, drawn, used, a);
  if (budget_draws_ > 0) assign_budget(run, a, *field, bases, budget_draws_, seed_, parallel_, a);
  a.uncertainty_draws = static_cast<int>(used);
  a.uncertainty_shrink = bases.shrink;
  const double datasheet = uncertainty::datasheet_relative_noise(run.meta.sensors);
  if (auto flag = uncertainty::noise_disagreement(a.measurement.rest_noise, datasheet)) a.flags.push_back(*flag);
  char note[640];
  std::snprintf(note, sizeof note,
                "GUM, k = 2: %d Monte Carlo draws of the error field (%s; bias walk %.2f and %.2f µg/√s from the "
                "data sheet; sensor model: %s; PSD strips, their offsets and nonlinearity), path at %.0f Hz",
                a.uncertainty_draws, uncertainty::noise_source_text(a.measurement.rest_noise, datasheet).c_str(),
                in_.bias_walk_ug_per_rts[0], in_.bias_walk_ug_per_rts[1], a.uncertainty_source.c_str(),
                a.measurement.fs_hz / static_cast<double>(q_));
  a.uncertainty_note = note;
}

}  // namespace eical::dsp
