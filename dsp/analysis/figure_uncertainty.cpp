#include "dsp/analysis/figure_uncertainty.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/stream_seed.hpp"
#include "dsp/uncertainty/error_field.hpp"

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

struct Accumulator {
  std::vector<double> sum, sumsq;
  std::vector<int> count;
};

// The two paths the draws perturb, evaluated at the draws' rate. The measured one (the
// plug-in: what the error does to this machine's figures) and the ideal one, the set-point
// (what the error alone makes of them: for a range, an amplitude or a spread —
// |f(t + e) − f(t)| ≤ f(e) — a bound whatever the machine).
struct DrawBases {
  std::unique_ptr<SetPointCache> setpoint;  // both bases' and every draw's: one set-point
  EvaluationOptions eo;
  Analysis nominal, ideal;
  std::vector<FigureValue> f0, g0;  // their figures
  std::vector<double> at;           // the trace positions the draws perturb
};

// `decimated`: every q-th sample of the trace (fs/q); the triggers are kept.
DrawBases evaluate_bases(const Run& run, const Analysis& a, Measurement decimated, std::size_t q, std::size_t samples) {
  const Measurement& m = a.measurement;
  DrawBases b;
  b.eo.reference = false;
  b.eo.keep_trace = false;
  if (a.diagnostics) b.eo.cyclic_pitch_mm = a.diagnostics->cyclic_pitch_mm;
  b.nominal.measurement = std::move(decimated);
  b.nominal.measurement.fs_hz = m.fs_hz / static_cast<double>(q);
  b.nominal.measurement.triggers = m.triggers;
  b.nominal.measurement.start_index = m.start_index, b.nominal.measurement.motion_end_index = m.motion_end_index;
  b.nominal.dynamic = b.ideal.dynamic = a.dynamic, b.nominal.nbs = b.ideal.nbs = a.nbs;
  b.ideal.measurement = b.nominal.measurement;
  b.ideal.measurement.pos_mm = b.ideal.measurement.cmd_mm;
  b.setpoint = std::make_unique<SetPointCache>();
  b.eo.setpoint = b.setpoint.get();
  evaluate_program(run, b.nominal, b.eo);  // fills the set-point cache
  evaluate_program(run, b.ideal, b.eo);
  b.setpoint->frozen = true;  // the draws read it in parallel
  b.f0 = figures_of(b.nominal), b.g0 = figures_of(b.ideal);
  for (std::size_t i = 0; i < samples; i += q) b.at.push_back(static_cast<double>(i));
  return b;
}

// Per figure of a base, per element: the sums of the draws' offsets from the base.
std::vector<Accumulator> accumulators_for(const std::vector<FigureValue>& f) {
  std::vector<Accumulator> acc(f.size());
  for (std::size_t k = 0; k < f.size(); ++k) {
    const std::size_t e = f[k].values.size();
    acc[k].sum.assign(e, 0.0), acc[k].sumsq.assign(e, 0.0), acc[k].count.assign(e, 0);
  }
  return acc;
}

// A draw's figures into the sums (figures whose shape differs from the base's left out).
void accumulate(const std::vector<FigureValue>& base, const std::vector<FigureValue>& drawn,
                std::vector<Accumulator>& acc) {
  for (std::size_t k = 0; k < base.size(); ++k) {
    const FigureValue* v = find_figure(drawn, base[k].key);
    if (!v || v->values.size() != base[k].values.size()) continue;
    for (std::size_t e = 0; e < v->values.size(); ++e) {
      const double dv = v->values[e] - base[k].values[e];
      if (!std::isfinite(dv)) continue;
      acc[k].sum[e] += dv, acc[k].sumsq[e] += dv * dv, ++acc[k].count[e];
    }
  }
}

// The figures of a base with a draw's error (µm) added to its path. The draw perturbs the
// positions of `scratch` only: the rest of the base's measurement is copied into it once
// (the evaluation reads it, never writes it), not per draw (200 copies of every array, each
// mapped and faulted in afresh).
std::vector<FigureValue> perturbed_figures(const Run& run, const Analysis& a, const Analysis& base,
                                           const std::vector<Eigen::Vector3d>& err, const EvaluationOptions& eo,
                                           Measurement& scratch) {
  Analysis x;
  x.measurement = std::move(scratch);
  x.measurement.pos_mm.assign(base.measurement.pos_mm.begin(), base.measurement.pos_mm.end());
  for (std::size_t i = 0; i < err.size() && i < x.measurement.pos_mm.size(); ++i)
    x.measurement.pos_mm[i] += err[i] / 1000.0;
  x.dynamic = a.dynamic, x.nbs = a.nbs;
  evaluate_program(run, x, eo);
  std::vector<FigureValue> f = figures_of(x);
  scratch = std::move(x.measurement);
  return f;
}

struct DrawSums {
  std::vector<Accumulator> plug, bound;  // on the measured path, on the ideal one
};

struct DrawnFigures {
  std::vector<FigureValue> plug, bound;
};

// The seeded draws [from, to) of the error field, each added to both bases and evaluated.
// Contiguous blocks of draws are the executor's tasks (one copy of the bases' measurement a
// block); the sums are taken in draw order afterwards.
void draw_range(const Run& run, const Analysis& a, const uncertainty::ErrorField& field, const DrawBases& b,
                std::size_t from, std::size_t to, std::uint64_t seed, const ParallelFor& parallel,
                std::vector<std::optional<uncertainty::NoiseDraw>>& noise, std::vector<DrawnFigures>& drawn) {
  const std::size_t n = to - from;
  const std::size_t blocks = std::min<std::size_t>(n, kDrawBlocks);
  parallel(blocks, [&](std::size_t block) {
    std::vector<Eigen::Vector3d> err;
    Measurement nominal_scratch = b.nominal.measurement, ideal_scratch = b.ideal.measurement;
    for (std::size_t d = from + block * n / blocks; d < from + (block + 1) * n / blocks; ++d) {
      // Seeded by (seed, d) alone, so the draws may run in any order and on any thread.
      if (d < noise.size() && noise[d]) {  // its noise drawn already, from the same generator
        field.draw(std::move(*noise[d]), b.at, err);
      } else {
        std::mt19937_64 rng(stream_seed(seed, d));
        field.draw(rng, b.at, err);
      }
      drawn[d].plug = perturbed_figures(run, a, b.nominal, err, b.eo, nominal_scratch);
      drawn[d].bound = perturbed_figures(run, a, b.ideal, err, b.eo, ideal_scratch);
    }
  });
}

DrawSums sums_of(const DrawBases& b, const std::vector<DrawnFigures>& drawn, std::size_t n) {
  DrawSums s{accumulators_for(b.f0), accumulators_for(b.g0)};
  for (std::size_t d = 0; d < n; ++d)
    accumulate(b.f0, drawn[d].plug, s.plug), accumulate(b.g0, drawn[d].bound, s.bound);
  return s;
}

// U of element e of figure k of a set of draws (NaN when most draws could not evaluate it).
double u_of(const std::vector<Accumulator>& ac, std::size_t k, std::size_t e, bool plug_in, int draws) {
  const int c = ac[k].count[e];
  if (2 * c < draws) return std::numeric_limits<double>::quiet_NaN();
  const double mean = ac[k].sum[e] / c;
  const double sd = std::sqrt(std::max(0.0, (ac[k].sumsq[e] - c * mean * mean) / std::max(1, c - 1)));
  return plug_in ? expanded_uncertainty(mean, sd, c) : std::abs(mean) + 2.0 * sd;
}

std::size_t index_of(const std::vector<FigureValue>& f, const std::string& key) {
  std::size_t k = 0;
  while (k < f.size() && f[k].key != key) ++k;
  return k;
}

// U of a figure with `elements` values from the draws where the shapes agree, the larger
// of the plug-in and the ideal path's bound; empty when neither base has it in that shape.
std::vector<double> u_of_figure(const DrawBases& b, const DrawSums& s, int draws, const std::string& key,
                                std::size_t elements) {
  const std::size_t k = index_of(b.f0, key), j = index_of(b.g0, key);
  const bool plug = k < b.f0.size() && b.f0[k].values.size() == elements;
  const bool bound = j < b.g0.size() && b.g0[j].values.size() == elements;
  if (!plug && !bound) return {};
  std::vector<double> u(elements, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t e = 0; e < u.size(); ++e) {
    const double up = plug ? u_of(s.plug, k, e, true, draws) : std::numeric_limits<double>::quiet_NaN();
    const double ub = bound ? u_of(s.bound, j, e, false, draws) : std::numeric_limits<double>::quiet_NaN();
    u[e] = std::isfinite(up) && std::isfinite(ub) ? std::max(up, ub) : std::isfinite(up) ? up : ub;
  }
  return u;
}

// Figures of the full-rate analysis.
void assign_uncertainties(const DrawBases& b, const DrawSums& s, int draws, Analysis& a) {
  for (const FigureValue& full : figures_of(a)) {
    std::vector<double> u = u_of_figure(b, s, draws, full.key, full.values.size());
    if (!u.empty()) a.uncertainty_k2[full.key] = std::move(u);
  }
}

// The draws' sums and how many ran: all of them, or the screen's first ones when they
// already put U of its figure above its bound.
struct DrawOutcome {
  DrawSums sums;
  int used = 0;
};

DrawOutcome run_draws(const Run& run, const Analysis& a, const uncertainty::ErrorField& field, const DrawBases& b,
                      int draws, std::uint64_t seed, const ParallelFor& parallel,
                      const std::optional<AnalysisOptions::Uncertainty::StopAbove>& stop,
                      std::vector<std::optional<uncertainty::NoiseDraw>>& noise) {
  const auto n = static_cast<std::size_t>(draws);
  std::vector<DrawnFigures> drawn(n);
  const std::size_t first = stop ? static_cast<std::size_t>(std::clamp(stop->after_draws, 2, draws)) : n;
  draw_range(run, a, field, b, 0, first, seed, parallel, noise, drawn);
  if (first < n) {
    const int m = static_cast<int>(first);
    DrawSums screen = sums_of(b, drawn, first);
    const std::vector<double> u = u_of_figure(b, screen, m, stop->key, 1);
    if (u.size() == 1 && u[0] > stop->above) return {std::move(screen), m};
    draw_range(run, a, field, b, first, n, seed, parallel, noise, drawn);
  }
  return {sums_of(b, drawn, n), draws};
}

}  // namespace

double expanded_uncertainty(double mean_offset, double sd, int n) {
  if (n < 2) return kNaN;
  const double mc = 2.0 * sd / std::sqrt(static_cast<double>(n));
  const double bias = std::max(0.0, std::abs(mean_offset) - mc);
  return 2.0 * sd + bias / (std::numbers::sqrt2 - 1.0);
}

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
      seed_(options.uncertainty.seed),
      parallel_(options.parallel ? options.parallel : sequential_for()) {
  const Measurement& m = a.measurement;
  uncertainty::ErrorFieldInput& in = in_;
  in.fs_hz = m.fs_hz;
  in.delay_samples = a.dynamic == DynamicComp::none ? 0.0 : config.acquisition.daq_group_delay_samples;
  in.model = config.fusion;
  in.start_bias_sigma_um_s2 = m.supports.start_bias_sigma_um_s2;
  in.model_covariance = options.model_covariance ? *options.model_covariance
                                                 : uncertainty::datasheet_covariance(run.meta.sensors, m.fs_hz);
  in.sensor_noise_ug_per_rthz[0] = run.meta.sensors[0].noise_ug_per_rthz;
  in.sensor_noise_ug_per_rthz[1] = run.meta.sensors[1].noise_ug_per_rthz;
  in.g_mps2 = run.meta.site.g_mps2;
  for (int j = 0; j < 3; ++j) in.owner[static_cast<std::size_t>(j)] = axis_owner(run.meta.machine, j);

  // The schedule as the trace was actually fused: without the strips when they disagreed,
  // without any support when the fusion diverged (the trace stayed as integrated).
  uncertainty::FineSchedule fine;
  fine.schedule = &schedule;
  fine.samples = std::min(samples, schedule.flags.size());
  fine.index_at = std::move(index_at);
  fine.zupt_unused = zupt_unused;
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
  const DrawBases bases = evaluate_bases(run, a, std::exchange(nominal_, Measurement{}), q_, samples_);
  const DrawOutcome drew = run_draws(run, a, *field, bases, draws_, seed_, parallel_, stop_above_, noise_);
  noise_.clear();
  assign_uncertainties(bases, drew.sums, drew.used, a);
  a.uncertainty_draws = drew.used;
  char note[200];
  std::snprintf(note, sizeof note,
                "GUM, k = 2: %d Monte Carlo draws of the error field (noise and bias walk between the supports, sensor "
                "model: %s, PSD strips), path at %.0f Hz",
                drew.used, a.uncertainty_source.c_str(), a.measurement.fs_hz / static_cast<double>(q_));
  a.uncertainty_note = note;
}

}  // namespace eical::dsp
