#include "dsp/eval/circle_diagnostics.hpp"

#include "dsp/core/error.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {
namespace {

constexpr double kUmPerMm = 1000.0;

int sgn(double v, double eps) { return v > eps ? 1 : (v < -eps ? -1 : 0); }

// Commanded velocity by central differences (mm/s); the set-point is noise-free.
std::vector<Eigen::Vector2d> velocity(const CirclePass& p) {
  const std::size_t n = p.cmd_mm.size();
  std::vector<Eigen::Vector2d> v(n, Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1;
    const std::size_t b = i + 1 == n ? i : i + 1;
    if (b > a) v[i] = (p.cmd_mm[b] - p.cmd_mm[a]) * (p.fs_hz / static_cast<double>(b - a));
  }
  return v;
}

// Samples within `window` after a reversal of axis `a` (sign change of its velocity).
std::vector<bool> near_reversal(const std::vector<Eigen::Vector2d>& v, int a, std::size_t window, double eps) {
  std::vector<bool> mask(v.size(), false);
  int last = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const int s = sgn(v[i][a], eps);
    if (s != 0 && last != 0 && s != last)
      for (std::size_t k = i; k < std::min(v.size(), i + window); ++k) mask[k] = true;
    if (s != 0) last = s;
  }
  return mask;
}

// Fixed columns of the per-axis model (after the per-pass drift polynomials).
enum Col { scale, square, lag, backlash, lateral, cyc_sin, cyc_cos, bow, n_cols };

struct AxisFit {
  Eigen::VectorXd coef;  // fixed columns only
  std::vector<std::vector<double>> residual_mm;  // per pass, per sample
  double rms_mm = 0.0;
};

struct Sample {
  std::size_t pass, index;
};

// Least squares for axis `a` (0 = x, 1 = y). `use` selects the model columns; samples in
// `skip` (reversal windows) are left out of the fit but get residuals.
AxisFit fit_axis(const std::vector<CirclePass>& passes, const std::vector<std::vector<Eigen::Vector2d>>& vel,
                 const std::vector<std::vector<bool>>& skip, int a, const std::array<bool, n_cols>& use,
                 const DiagnosticsOptions& opt, double pitch_mm, double fixed_lag_s, double play_mm = 0.0) {
  // Backlash column: the lost motion as the slide sees it. With a play estimate it is the
  // play operator's output (the slide waits until the motor has crossed the play, so the
  // step after a reversal takes time); without one, the step −sgn(v)/2.
  std::vector<std::vector<double>> lost;
  for (std::size_t pi = 0; pi < passes.size(); ++pi) {
    const auto& p = passes[pi];
    auto& col = lost.emplace_back(p.cmd_mm.size(), 0.0);
    if (!(play_mm > 0.0)) {
      for (std::size_t i = 0; i < col.size(); ++i) col[i] = -0.5 * sgn(vel[pi][i][a], 1e-6);
      continue;
    }
    int d0 = 0;
    for (std::size_t i = 0; i < col.size() && d0 == 0; ++i) d0 = sgn(vel[pi][i][a], 1e-6);
    double slide = p.cmd_mm[0][a] - 0.5 * play_mm * d0;  // play taken up in the first direction
    for (std::size_t i = 0; i < col.size(); ++i) {
      const double x = p.cmd_mm[i][a];
      slide = std::clamp(slide, x - 0.5 * play_mm, x + 0.5 * play_mm);
      col[i] = (slide - x) / play_mm;
    }
  }
  const int b = 1 - a;
  const double R = opt.radius_mm;
  const double eps = 1e-6;
  const std::size_t n_pass = passes.size();
  std::vector<int> col_of(n_cols, -1);
  int n_fixed = 0;
  for (int c = 0; c < n_cols; ++c)
    if (use[static_cast<std::size_t>(c)]) col_of[static_cast<std::size_t>(c)] = n_fixed++;
  const int n_poly = 3 * static_cast<int>(n_pass);

  auto row_of = [&](std::size_t pi, std::size_t i, auto&& row, double& target) {
    const CirclePass& p = passes[pi];
    const Eigen::Vector2d c = p.cmd_mm[i];
    const Eigen::Vector2d v = vel[pi][i];
    const double t = (static_cast<double>(i) / static_cast<double>(p.cmd_mm.size()) - 0.5);  // scaled time
    row.setZero();
    row(static_cast<int>(3 * pi)) = 1.0;
    row(static_cast<int>(3 * pi + 1)) = t;
    row(static_cast<int>(3 * pi + 2)) = t * t;
    auto put = [&](Col col, double value) {
      if (col_of[col] >= 0) row(n_poly + col_of[col]) = value;
    };
    put(scale, c[a] - opt.centre_mm[a]);
    put(square, a == 0 ? -(c[1] - opt.centre_mm[1]) : 0.0);
    put(lag, -v[a]);
    put(backlash, lost[pi][i]);
    put(lateral, 0.5 * sgn(v[b], eps));
    put(cyc_sin, std::sin(2.0 * std::numbers::pi * c[a] / pitch_mm));
    put(cyc_cos, std::cos(2.0 * std::numbers::pi * c[a] / pitch_mm));
    const double u = (c[b] - opt.centre_mm[b]) / R;
    put(bow, u * u);
    target = p.meas_mm[i][a] - c[a] + fixed_lag_s * v[a];  // a fixed lag is moved to the left side
  };

  std::vector<Sample> rows;
  for (std::size_t pi = 0; pi < n_pass; ++pi)
    for (std::size_t i = 0; i < passes[pi].cmd_mm.size(); ++i)
      if (!skip[pi][i]) rows.push_back({pi, i});
  const int n_unknown = n_poly + n_fixed;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(rows.size()), n_unknown);
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    double target = 0.0;
    row_of(rows[r].pass, rows[r].index, A.row(static_cast<Eigen::Index>(r)), target);
    y(static_cast<Eigen::Index>(r)) = target;
  }
  // Column scaling keeps the QR well conditioned (mm, mm/s and ±0.5 columns differ a lot).
  Eigen::VectorXd norm = A.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < norm.size(); ++c)
    if (norm(c) <= 0.0) norm(c) = 1.0;
  const Eigen::MatrixXd As = A * norm.cwiseInverse().asDiagonal();
  const Eigen::VectorXd x = As.colPivHouseholderQr().solve(y).cwiseQuotient(norm);

  AxisFit fit;
  fit.coef = Eigen::VectorXd::Zero(n_cols);
  for (int c = 0; c < n_cols; ++c)
    if (col_of[static_cast<std::size_t>(c)] >= 0) fit.coef(c) = x(n_poly + col_of[static_cast<std::size_t>(c)]);
  fit.residual_mm.resize(n_pass);
  double ss = 0.0;
  std::size_t n_ss = 0;
  Eigen::RowVectorXd row(n_unknown);
  for (std::size_t pi = 0; pi < n_pass; ++pi) {
    fit.residual_mm[pi].resize(passes[pi].cmd_mm.size());
    for (std::size_t i = 0; i < passes[pi].cmd_mm.size(); ++i) {
      double target = 0.0;
      row_of(pi, i, row, target);
      const double r = target - row.dot(x);
      fit.residual_mm[pi][i] = r;
      if (!skip[pi][i]) {
        ss += r * r;
        ++n_ss;
      }
    }
  }
  fit.rms_mm = n_ss > 0 ? std::sqrt(ss / static_cast<double>(n_ss)) : 0.0;
  return fit;
}

// Mean signed peak of the residual in the window after each reversal of axis `a`.
double reversal_spike_um(const std::vector<CirclePass>& passes, const std::vector<std::vector<Eigen::Vector2d>>& vel,
                         const AxisFit& fit, int a, std::size_t window) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t pi = 0; pi < passes.size(); ++pi) {
    int last = 0;
    for (std::size_t i = 0; i < vel[pi].size(); ++i) {
      const int s = sgn(vel[pi][i][a], 1e-6);
      if (s != 0 && last != 0 && s != last && i + window <= vel[pi].size()) {
        double peak = 0.0;
        for (std::size_t k = i; k < i + window; ++k)
          if (std::abs(fit.residual_mm[pi][k]) > std::abs(peak)) peak = fit.residual_mm[pi][k];
        // Positive when the axis lags behind its new direction (friction holds it at the
        // reversal, the usual reversal spike); an overshoot is negative.
        sum -= peak * s;
        ++count;
      }
      if (s != 0) last = s;
    }
  }
  return count > 0 ? sum / count * kUmPerMm : 0.0;
}

}  // namespace

CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& opt) {
  if (passes.empty()) throw InputError("circle diagnostics: no pass to evaluate");
  if (!(opt.radius_mm > 0.0)) throw InputError("circle diagnostics: radius must be positive");
  bool both_directions = false;
  for (const auto& p : passes) {
    if (p.cmd_mm.size() != p.meas_mm.size())
      throw InputError("circle diagnostics: commanded and measured traces differ in length");
    if (p.cmd_mm.size() < 100) throw InputError("circle diagnostics: a pass holds fewer than 100 samples");
    if (!(p.fs_hz > 0.0)) throw InputError("circle diagnostics: fs_hz must be positive");
    if (p.direction != passes.front().direction) both_directions = true;
    for (std::size_t i = 0; i < p.cmd_mm.size(); ++i)
      if (!p.cmd_mm[i].allFinite() || !p.meas_mm[i].allFinite())
        throw InputError("circle diagnostics: non-finite position at sample " + std::to_string(i));
  }

  std::vector<std::vector<Eigen::Vector2d>> vel;
  for (const auto& p : passes) vel.push_back(velocity(p));
  const auto window = static_cast<std::size_t>(std::lround(opt.spike_window_s * passes.front().fs_hz));
  std::array<std::vector<std::vector<bool>>, 2> skip;
  for (int a = 0; a < 2; ++a)
    for (const auto& v : vel) skip[static_cast<std::size_t>(a)].push_back(near_reversal(v, a, window, 1e-6));

  std::array<bool, n_cols> use{};
  use.fill(true);
  // A pitch is identifiable only with at least two periods over the diameter; longer ones
  // are collinear with scale, offset and bow.
  std::vector<double> pitches;
  if (opt.cyclic_pitch_mm) {
    pitches = {*opt.cyclic_pitch_mm};
  } else {
    for (double p : {1.0, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0})
      if (p <= opt.radius_mm) pitches.push_back(p);
    if (pitches.empty()) pitches = {opt.radius_mm};
  }

  CircleDiagnostics d;
  // Y first: its lag is identifiable from one direction (v_y follows cos θ, squareness
  // sits in the x equation only), and a single-direction x fit borrows it.
  std::array<AxisFit, 2> fits;
  double best_pitch = pitches.front();
  double best_rms = INFINITY;
  for (double p : pitches) {
    const double rms = fit_axis(passes, vel, skip[1], 1, use, opt, p, 0.0).rms_mm +
                       fit_axis(passes, vel, skip[0], 0, use, opt, p, 0.0).rms_mm;
    if (rms < best_rms) best_rms = rms, best_pitch = p;
  }
  // Twice: first with a step for the backlash, then with the play operator of the play
  // just found (a sharp step would leave the play's crossing time as a false reversal spike).
  double play_mm[2] = {0.0, 0.0};
  for (int round = 0; round < 2; ++round) {
    fits[1] = fit_axis(passes, vel, skip[1], 1, use, opt, best_pitch, 0.0, play_mm[1]);
    if (both_directions) {
      fits[0] = fit_axis(passes, vel, skip[0], 0, use, opt, best_pitch, 0.0, play_mm[0]);
    } else {
      auto use_x = use;
      use_x[lag] = false;
      fits[0] = fit_axis(passes, vel, skip[0], 0, use_x, opt, best_pitch, fits[1].coef(lag), play_mm[0]);
      fits[0].coef(lag) = fits[1].coef(lag);
    }
    for (int a = 0; a < 2; ++a) play_mm[a] = std::max(0.0, fits[static_cast<std::size_t>(a)].coef(backlash));
  }
  if (both_directions) d.servo_and_squareness_separated = true;
  else d.notes.push_back("one direction only: servo mismatch cannot be separated from squareness; equal lags assumed");
  const Eigen::VectorXd& cx = fits[0].coef;
  const Eigen::VectorXd& cy = fits[1].coef;
  d.backlash_x_um = cx(backlash) * kUmPerMm;
  d.backlash_y_um = cy(backlash) * kUmPerMm;
  d.lateral_play_x_um = cx(lateral) * kUmPerMm;
  d.lateral_play_y_um = cy(lateral) * kUmPerMm;
  d.cyclic_error_x_um = std::hypot(cx(cyc_sin), cx(cyc_cos)) * kUmPerMm;
  d.cyclic_error_y_um = std::hypot(cy(cyc_sin), cy(cyc_cos)) * kUmPerMm;
  d.cyclic_pitch_mm = best_pitch;
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
  d.reversal_spike_x_um = reversal_spike_um(passes, vel, fits[0], 0, window);
  d.reversal_spike_y_um = reversal_spike_um(passes, vel, fits[1], 1, window);

  // What the model leaves (RMS over the samples outside the reversal windows): radially
  // the vibration class, per axis the stick-slip class.
  double ss_rad = 0.0, ss_axis[2] = {0.0, 0.0};
  std::size_t n = 0;
  for (std::size_t pi = 0; pi < passes.size(); ++pi)
    for (std::size_t i = 0; i < passes[pi].cmd_mm.size(); ++i) {
      if (skip[0][pi][i] || skip[1][pi][i]) continue;
      const Eigen::Vector2d r(fits[0].residual_mm[pi][i], fits[1].residual_mm[pi][i]);
      Eigen::Vector2d radial = passes[pi].cmd_mm[i] - opt.centre_mm;
      if (radial.norm() <= 0.0) continue;
      radial.normalize();
      ss_rad += std::pow(r.dot(radial), 2);
      ss_axis[0] += r[0] * r[0], ss_axis[1] += r[1] * r[1];
      ++n;
    }
  if (n > 0) {
    if (opt.feed_mm_min > 0.0 && opt.feed_mm_min <= opt.creep_feed_mm_min) {
      // Creep feed: the fast residual of each axis is its slide sticking and slipping — a
      // sawtooth (or triangle) between 0 and the lag A, whose RMS is A/(2√3). Its mean lag
      // A/2 against the direction of motion reads as backlash A.
      const double ax = std::sqrt(ss_axis[0] / static_cast<double>(n)), ay = std::sqrt(ss_axis[1] / static_cast<double>(n));
      d.stick_slip_um = 2.0 * std::sqrt(3.0) * std::max(ax, ay) * kUmPerMm;
      d.notes.push_back("creep feed: the fast residual is reported as stick-slip (its mean lag also reads as backlash)");
    } else {
      d.vibration_um = std::sqrt(ss_rad / static_cast<double>(n)) * kUmPerMm;
    }
  }
  d.residual_rms_um = std::hypot(fits[0].rms_mm, fits[1].rms_mm) * kUmPerMm;
  return d;
}

}  // namespace eical::dsp::eval
