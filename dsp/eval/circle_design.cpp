// The circle diagnostics from a set-point's design (circle_diagnostics.hpp): what the fit
// takes from the set-point alone made once, then each path's fit from its measured samples.
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/eval/circle_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

namespace eical::dsp::eval {

class CircleDesign {
 public:
  std::vector<PassReplay::Pass> passes;
  DiagnosticsOptions opt;
  std::vector<double> pitches;
  std::size_t q = 1, window = 0;
  bool both_directions = false;
  // The walks' records at the fits' rate and at the full rate (`full` empty when that is
  // the fits'), their meas unset; per record and axis the columns (Walked::cols).
  std::vector<diagnostics_fit::Walked> fit, full;
  std::vector<double> fit_cols, full_cols;
  std::array<std::vector<int>, 2> d0;           // per axis and pass: the first direction of motion
  std::vector<diagnostics_fit::AxisGram> gram;  // round one's normal equations, the target zero

  [[nodiscard]] std::size_t width() const noexcept { return 9 + 2 * pitches.size(); }
  // Throws unless `p` are the passes and `o` the options this was made of (the options
  // that decide the columns, the windows and the pitches).
  void check(const std::vector<CirclePass>& p, const DiagnosticsOptions& o) const {
    bool same = o.radius_mm == opt.radius_mm && o.centre_mm == opt.centre_mm &&
                o.cyclic_pitch_mm == opt.cyclic_pitch_mm && o.spike_window_s == opt.spike_window_s &&
                p.size() == passes.size();
    for (std::size_t k = 0; same && k < p.size(); ++k)
      same = p[k].direction == passes[k].direction && p[k].fs_hz == passes[k].fs_hz &&
             p[k].cmd_mm.size() == passes[k].samples && p[k].meas_mm.size() == passes[k].samples;
    for (std::size_t k = 0; same && k < fit.size(); k += std::max<std::size_t>(1, fit.size() / 16))
      same = fit[k].cmd == p[fit[k].pass].cmd_mm[fit[k].i * q];
    if (!same) throw InputError("circle diagnostics: the design was made of another set-point or other options");
  }
};

namespace diagnostics_fit {
namespace {

// The measured sample of a design's record (q: the record's rate divisor of the passes').
const Eigen::Vector2d& measured(const std::vector<CirclePass>& passes, const Walked& r, std::size_t q) {
  const Eigen::Vector2d& m = passes[r.pass].meas_mm[r.i * q];
  if (!m.allFinite()) throw InputError("circle diagnostics: non-finite position at sample " + std::to_string(r.i * q));
  return m;
}

// The records of a walk and every record's columns (the backlash as a step, every pitch).
void record_walk(PassReplay& replay, std::size_t window, std::array<AxisModel, 2>& model, std::vector<Walked>& out,
                 std::vector<double>& cols) {
  const std::size_t width = 9 + 2 * model[0].pitches_mm.size();
  walk(replay, window, [&](const Walked& w) {
    out.push_back(w);
    for (int a = 0; a < 2; ++a) {
      const std::size_t at = cols.size();
      cols.resize(at + width);
      double target = 0.0;
      model[a].row(w, &cols[at], &cols[at + 9], target);
    }
  });
}

// Round one's normal equations: the design's, with the measured path's target products.
std::vector<AxisGram> every_pitch_from(const CircleDesign& d, const std::vector<CirclePass>& passes) {
  std::vector<AxisGram> gram = d.gram;
  const std::size_t w = d.width();
  constexpr auto kT = static_cast<Eigen::Index>(AxisGram::kTarget);
  for (std::size_t k = 0; k < d.fit.size(); ++k) {
    const Walked& r = d.fit[k];
    const Eigen::Vector2d& m = measured(passes, r, d.q);
    for (int a = 0; a < 2; ++a) {
      if (r.skip[a]) continue;
      const double y = m[a] - r.cmd[a];
      const double* c = &d.fit_cols[(2 * k + static_cast<std::size_t>(a)) * w];
      Eigen::MatrixXd& g = gram[static_cast<std::size_t>(a)].m[r.pass];
      for (Eigen::Index j = 0; j < kT; ++j) g(kT, j) += y * c[j];
      g(kT, kT) += y * y;
      for (Eigen::Index j = kT; j < static_cast<Eigen::Index>(w); ++j) g(j + 1, kT) += y * c[j];
    }
  }
  return gram;
}

// Round two's normal equations: round one's at the best pitch, the backlash column
// replaced by the play operator's (model: its play, state run through every record).
std::vector<AxisGram> best_pitch_from(const CircleDesign& d, const std::vector<CirclePass>& passes,
                                      const std::vector<AxisGram>& every, std::size_t best,
                                      std::array<AxisModel, 2>& model) {
  const std::size_t w = d.width(), n_pass = d.passes.size();
  const std::size_t from[12] = {
      0, 1, 2, 3, 4, 5, 6, 7, 8, AxisGram::kTarget, AxisGram::kCyc + 2 * best, AxisGram::kCyc + 2 * best + 1};
  constexpr Eigen::Index kB = 6;  // the backlash column
  std::vector<AxisGram> gram;
  for (std::size_t a = 0; a < 2; ++a) {
    gram.emplace_back(n_pass, 1);
    gram[a].rows = every[a].rows;
    for (std::size_t p = 0; p < n_pass; ++p)
      for (Eigen::Index r = 0; r < 12; ++r)
        for (Eigen::Index c = 0; c <= r; ++c)
          gram[a].m[p](r, c) =
              r == kB || c == kB ? 0.0
                                 : every[a].at(p, from[static_cast<std::size_t>(r)], from[static_cast<std::size_t>(c)]);
  }
  for (std::size_t k = 0; k < d.fit.size(); ++k) {
    const Walked& r = d.fit[k];
    const Eigen::Vector2d& m = passes[r.pass].meas_mm[r.i * d.q];  // every_pitch_from() checked it
    for (int a = 0; a < 2; ++a) {
      const double b = model[static_cast<std::size_t>(a)].backlash_column(r);
      if (r.skip[a]) continue;
      const double* c = &d.fit_cols[(2 * k + static_cast<std::size_t>(a)) * w];
      Eigen::MatrixXd& g = gram[static_cast<std::size_t>(a)].m[r.pass];
      for (Eigen::Index j = 0; j < kB; ++j) g(kB, j) += b * c[j];
      g(kB, kB) += b * b;
      g(7, kB) += b * c[7], g(8, kB) += b * c[8];
      g(9, kB) += b * (m[a] - r.cmd[a]);
      g(10, kB) += b * c[9 + 2 * best], g(11, kB) += b * c[10 + 2 * best];
    }
  }
  return gram;
}

// The records at the full rate with the measured path, in order.
template <class F>
void replay_full(const CircleDesign& d, const std::vector<CirclePass>& passes, F&& f) {
  const bool own = !d.full.empty();
  const std::vector<Walked>& recs = own ? d.full : d.fit;
  const std::vector<double>& cols = own ? d.full_cols : d.fit_cols;
  const std::size_t w = d.width();
  for (std::size_t k = 0; k < recs.size(); ++k) {
    Walked r = recs[k];
    r.meas = measured(passes, r, own ? 1 : d.q);
    r.cols[0] = &cols[2 * k * w], r.cols[1] = &cols[(2 * k + 1) * w];
    f(r);
  }
}

}  // namespace
}  // namespace diagnostics_fit

std::shared_ptr<const CircleDesign> circle_design(const std::vector<CirclePass>& passes,
                                                  const DiagnosticsOptions& options) {
  using namespace diagnostics_fit;
  for (const auto& p : passes)
    if (p.cmd_mm.size() != p.meas_mm.size())
      throw InputError("circle diagnostics: commanded and measured traces differ in length");
  StoredPasses replay(passes, StoredPasses::kSetPointOnly);  // a design reads no measurement
  auto d = std::make_shared<CircleDesign>();
  d->passes = replay.passes();
  d->opt = options;
  d->both_directions = check_passes(d->passes, options);
  d->pitches = candidate_pitches(options);
  const double fs_hz = d->passes.front().fs_hz;
  d->q = static_cast<std::size_t>(std::max(1.0, std::floor(fs_hz / kFitRateHz)));
  d->window = static_cast<std::size_t>(std::lround(options.spike_window_s * fs_hz));
  DecimatedPasses fit_replay(replay, d->q);
  const auto fit_window =
      static_cast<std::size_t>(std::lround(options.spike_window_s * fit_replay.passes().front().fs_hz));
  std::array<AxisModel, 2> model = step_models(options, d->pitches, passes.size());
  record_walk(fit_replay, fit_window, model, d->fit, d->fit_cols);
  if (d->q > 1) record_walk(replay, d->window, model, d->full, d->full_cols);
  // Round one's columns as accumulate_every_pitch() sums them, the target zero.
  for (int a = 0; a < 2; ++a) d->gram.emplace_back(passes.size(), d->pitches.size());
  const std::size_t w = d->width();
  for (auto& d0 : d->d0) d0.assign(passes.size(), 0);
  for (std::size_t k = 0; k < d->fit.size(); ++k) {
    const Walked& r = d->fit[k];
    for (std::size_t a = 0; a < 2; ++a) {
      if (d->d0[a][r.pass] == 0) d->d0[a][r.pass] = sgn(r.vel[static_cast<Eigen::Index>(a)], 1e-6);
      if (r.skip[a]) continue;
      const double* c = &d->fit_cols[(2 * k + a) * w];
      d->gram[a].add_row(r.pass, c, 0.0, c + 9, w - 9);
    }
  }
  for (auto& g : d->gram) g.flush();
  return d;
}

CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& opt,
                                  const CircleDesign& design) {
  using namespace diagnostics_fit;
  design.check(passes, opt);
  const std::vector<double>& pitches = design.pitches;
  std::array<AxisModel, 2> model = step_models(opt, pitches, passes.size());
  for (std::size_t a = 0; a < 2; ++a) model[a].d0 = design.d0[a];
  const std::vector<AxisGram> gram = every_pitch_from(design, passes);
  const std::size_t best = search_pitch(gram, pitches.size());
  const AxisFits round_one = fit_axes(gram, best, design.both_directions);
  for (std::size_t a = 0; a < 2; ++a) {
    model[a].set_pitches({pitches[best]});
    model[a].cached_cyc_first = 2 * best;
    model[a].play_mm = std::max(0.0, round_one.axis[a].coef(backlash));
  }
  const AxisFits fits = fit_axes(best_pitch_from(design, passes, gram, best, model), 0, design.both_directions);
  CircleDiagnostics d;
  report_fit(fits, pitches[best], design.both_directions, d);
  ResidualMeter meter(model, fits, opt.centre_mm, design.window);
  replay_full(design, passes, [&meter](const Walked& w) { meter.add(w); });
  report_residuals(meter.sums(), opt, d);
  return d;
}

}  // namespace eical::dsp::eval
