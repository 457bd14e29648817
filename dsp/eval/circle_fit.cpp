#include "dsp/eval/circle_fit.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/units.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::dsp::eval::diagnostics_fit {

using units::kUmPerMm;

// The least-squares fit of one axis from its normal equations: columns `use`, cyclic
// columns of pitch k, a fixed lag moved to the target (target + L·v).
AxisFit solve_axis(const AxisGram& g, std::size_t k, const std::array<bool, n_cols>& use, double fixed_lag_s) {
  const std::size_t n_pass = g.m.size();
  const std::size_t tgt = AxisGram::kTarget;
  // Gram column of each fixed model column (lag is 5 even when not used: the fixed lag).
  const std::size_t gcol[n_cols] = {3, 4, 5, 6, 7, AxisGram::kCyc + 2 * k, AxisGram::kCyc + 2 * k + 1, 8};
  AxisFit fit;
  fit.col_of.assign(n_cols, -1);
  int n_fixed = 0;
  for (int c = 0; c < n_cols; ++c)
    if (use[static_cast<std::size_t>(c)]) fit.col_of[static_cast<std::size_t>(c)] = n_fixed++;
  const auto n_poly = static_cast<Eigen::Index>(3 * n_pass);
  const Eigen::Index n_unknown = n_poly + n_fixed;
  // Unknown u → (pass or all, Gram column).
  struct Where {
    std::size_t pass;  // SIZE_MAX: every pass (a fixed column)
    std::size_t col;
  };
  std::vector<Where> where;
  for (std::size_t p = 0; p < n_pass; ++p)
    for (std::size_t j = 0; j < 3; ++j) where.push_back({p, j});
  for (int c = 0; c < n_cols; ++c)
    if (use[static_cast<std::size_t>(c)]) where.push_back({SIZE_MAX, gcol[c]});
  auto sum = [&](const Where& u, std::size_t col) {  // Σ over the rows of feature(u)·feature(col)
    if (u.pass != SIZE_MAX) return g.at(u.pass, u.col, col);
    double s = 0.0;
    for (std::size_t p = 0; p < n_pass; ++p) s += g.at(p, u.col, col);
    return s;
  };
  Eigen::MatrixXd G(n_unknown, n_unknown);
  Eigen::VectorXd b(n_unknown);
  for (Eigen::Index u = 0; u < n_unknown; ++u) {
    const Where& wu = where[static_cast<std::size_t>(u)];
    for (Eigen::Index v = 0; v <= u; ++v) {
      const Where& wv = where[static_cast<std::size_t>(v)];
      double val = 0.0;
      if (wu.pass != SIZE_MAX && wv.pass != SIZE_MAX)
        val = wu.pass == wv.pass ? g.at(wu.pass, wu.col, wv.col) : 0.0;
      else if (wu.pass != SIZE_MAX)
        val = g.at(wu.pass, wu.col, wv.col);
      else if (wv.pass != SIZE_MAX)
        val = g.at(wv.pass, wv.col, wu.col);
      else
        val = sum(wu, wv.col);
      G(u, v) = G(v, u) = val;
    }
    // Target + L·v with the lag column −v: Σ a·(t + L·v) = Σ a·t − L·Σ a·lag.
    b(u) = sum(wu, tgt) - fixed_lag_s * sum(wu, gcol[lag]);
  }
  double tt = 0.0, t_lag = 0.0, lag_lag = 0.0;
  std::size_t rows = 0;
  for (std::size_t p = 0; p < n_pass; ++p)
    tt += g.at(p, tgt, tgt), t_lag += g.at(p, tgt, gcol[lag]), lag_lag += g.at(p, gcol[lag], gcol[lag]),
        rows += g.rows[p];
  tt += -2.0 * fixed_lag_s * t_lag + fixed_lag_s * fixed_lag_s * lag_lag;
  // Column scaling keeps the solution well conditioned (mm, mm/s and ±0.5 columns differ a lot).
  Eigen::VectorXd norm = G.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Eigen::Index c = 0; c < norm.size(); ++c)
    if (norm(c) <= 0.0) norm(c) = 1.0;
  const Eigen::VectorXd inv = norm.cwiseInverse();
  const Eigen::MatrixXd Gs = inv.asDiagonal() * G * inv.asDiagonal();
  fit.x = Gs.colPivHouseholderQr().solve(inv.cwiseProduct(b)).cwiseQuotient(norm);
  fit.n_poly = static_cast<std::size_t>(n_poly);
  fit.coef = Eigen::VectorXd::Zero(n_cols);
  for (int c = 0; c < n_cols; ++c)
    if (fit.col_of[static_cast<std::size_t>(c)] >= 0)
      fit.coef(c) = fit.x(n_poly + fit.col_of[static_cast<std::size_t>(c)]);
  const double rss = tt - 2.0 * fit.x.dot(b) + fit.x.dot(G * fit.x);
  fit.rms_mm = rows > 0 ? std::sqrt(std::max(rss, 0.0) / static_cast<double>(rows)) : 0.0;
  return fit;
}

// Throws when the passes cannot be evaluated; whether they go round in both directions.
bool check_passes(const std::vector<PassReplay::Pass>& passes, const DiagnosticsOptions& opt) {
  if (passes.empty()) throw InputError("circle diagnostics: no pass to evaluate");
  if (!(opt.radius_mm > 0.0)) throw InputError("circle diagnostics: radius must be positive");
  bool both_directions = false;
  for (const auto& p : passes) {
    if (p.samples < 100) throw InputError("circle diagnostics: a pass holds fewer than 100 samples");
    if (!(p.fs_hz > 0.0)) throw InputError("circle diagnostics: fs_hz must be positive");
    if (p.direction != passes.front().direction) both_directions = true;
  }
  return both_directions;
}

// The pitches searched for the cyclic error. A pitch is identifiable only with at least two
// periods over the diameter; longer ones are collinear with scale, offset and bow.
std::vector<double> candidate_pitches(const DiagnosticsOptions& opt) {
  if (opt.cyclic_pitch_mm) return {*opt.cyclic_pitch_mm};
  std::vector<double> pitches;
  for (double p : {1.0, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0})
    if (p <= opt.radius_mm) pitches.push_back(p);
  if (pitches.empty()) pitches = {opt.radius_mm};
  return pitches;
}

std::array<bool, n_cols> every_column() {
  std::array<bool, n_cols> use{};
  use.fill(true);
  return use;
}
std::array<bool, n_cols> every_column_but_lag() {
  auto use = every_column();
  use[lag] = false;
  return use;
}

// Both axes' models with the backlash as a step, searching `pitches`.
std::array<AxisModel, 2> step_models(const DiagnosticsOptions& opt, const std::vector<double>& pitches,
                                     std::size_t n_pass) {
  std::array<AxisModel, 2> model;
  for (int a = 0; a < 2; ++a) {
    model[a].a = a, model[a].opt = opt;
    model[a].set_pitches(pitches);
    model[a].d0.assign(n_pass, 0);
  }
  return model;
}

// The pitch (index) whose fit leaves the least, both axes.
std::size_t search_pitch(const std::vector<AxisGram>& gram, std::size_t n_pitch) {
  const auto use = every_column();
  std::size_t best = 0;
  double best_rms = kInf;
  for (std::size_t k = 0; k < n_pitch; ++k) {
    const double rms = solve_axis(gram[1], k, use, 0.0).rms_mm + solve_axis(gram[0], k, use, 0.0).rms_mm;
    if (rms < best_rms) best_rms = rms, best = k;
  }
  return best;
}

// Both axes at pitch k. Y first: its lag is identifiable from one direction (v_y follows
// cos θ, squareness sits in the x equation only), and a single-direction x fit borrows it.
AxisFits fit_axes(const std::vector<AxisGram>& gram, std::size_t k, bool both_directions) {
  AxisFits fits;
  fits.axis[1] = solve_axis(gram[1], k, every_column(), 0.0);
  fits.fixed_lag_x_s = both_directions ? 0.0 : fits.axis[1].coef(lag);
  fits.axis[0] = both_directions ? solve_axis(gram[0], k, every_column(), 0.0)
                                 : solve_axis(gram[0], k, every_column_but_lag(), fits.fixed_lag_x_s);
  if (!both_directions) fits.axis[0].coef(lag) = fits.axis[1].coef(lag);
  return fits;
}

// The fitted machine errors into the diagnostics, in ballbar conventions.
void report_fit(const AxisFits& fits, double pitch_mm, bool both_directions, CircleDiagnostics& d) {
  if (both_directions)
    d.servo_and_squareness_separated = true;
  else
    d.notes.emplace_back("one direction only: servo mismatch cannot be separated from squareness; equal lags assumed");
  const Eigen::VectorXd& cx = fits.axis[0].coef;
  const Eigen::VectorXd& cy = fits.axis[1].coef;
  d.backlash_x_um = cx(backlash) * kUmPerMm;
  d.backlash_y_um = cy(backlash) * kUmPerMm;
  d.lateral_play_x_um = cx(lateral) * kUmPerMm;
  d.lateral_play_y_um = cy(lateral) * kUmPerMm;
  d.cyclic_error_x_um = std::hypot(cx(cyc_sin), cx(cyc_cos)) * kUmPerMm;
  d.cyclic_error_y_um = std::hypot(cy(cyc_sin), cy(cyc_cos)) * kUmPerMm;
  d.cyclic_pitch_mm = pitch_mm;
  d.lag_x_ms = cx(lag) * 1e3;
  d.lag_y_ms = cy(lag) * 1e3;
  d.servo_mismatch_ms = d.lag_x_ms - d.lag_y_ms;
  d.squareness_urad = cx(square) * 1e6;
  d.scale_mismatch_ppm = (cx(scale) - cy(scale)) * 1e6;
  // Bow of X's travel is seen on y, and the other way round; reported as the deviation at
  // mid-travel relative to the ends of the circle's span (the u² column is zero at mid-travel
  // and one at the ends, hence the sign).
  d.straightness_x_um = -cy(bow) * kUmPerMm;
  d.straightness_y_um = -cx(bow) * kUmPerMm;
}

// Reversal spikes, the fast residual (stick-slip at creep feed, else vibration) and the fit's RMS.
void report_residuals(const ResidualSums& s, const DiagnosticsOptions& opt, CircleDiagnostics& d) {
  d.reversal_spike_x_um =
      s.spike_count[0] > 0 ? s.spike_sum[0] / s.spike_count[0] * kUmPerMm : CircleDiagnostics::kNotEvaluated;
  d.reversal_spike_y_um =
      s.spike_count[1] > 0 ? s.spike_sum[1] / s.spike_count[1] * kUmPerMm : CircleDiagnostics::kNotEvaluated;
  if (s.n > 0) {
    if (opt.feed_mm_min > 0.0 && opt.feed_mm_min <= opt.creep_feed_mm_min) {
      // Creep feed: the fast residual of each axis is its slide sticking and slipping — a
      // sawtooth (or triangle) between 0 and the lag A, whose RMS is A/(2√3). Its mean lag
      // A/2 against the direction of motion reads as backlash A.
      const double ax = std::sqrt(s.ss_axis[0] / static_cast<double>(s.n)),
                   ay = std::sqrt(s.ss_axis[1] / static_cast<double>(s.n));
      d.stick_slip_um = 2.0 * std::sqrt(3.0) * std::max(ax, ay) * kUmPerMm;
      d.notes.emplace_back(
          "creep feed: the fast residual is reported as stick-slip (its mean lag also reads as backlash); vibration "
          "is not evaluated at creep feed");
    } else {
      d.vibration_um = std::sqrt(s.ss_rad / static_cast<double>(s.n)) * kUmPerMm;
      char note[160];
      std::snprintf(note, sizeof note,
                    "above the creep feed the fast residual is vibration: stick-slip is not evaluated (a test at "
                    "%.0f mm/min or less shows it)",
                    opt.creep_feed_mm_min);
      d.notes.emplace_back(note);
    }
  }
  const double rms_x = s.n_fit[0] > 0 ? std::sqrt(s.ss_fit[0] / static_cast<double>(s.n_fit[0])) : 0.0;
  const double rms_y = s.n_fit[1] > 0 ? std::sqrt(s.ss_fit[1] / static_cast<double>(s.n_fit[1])) : 0.0;
  d.residual_rms_um = std::hypot(rms_x, rms_y) * kUmPerMm;
}

}  // namespace eical::dsp::eval::diagnostics_fit
