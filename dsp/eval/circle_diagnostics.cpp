#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/units.hpp"

#include "dsp/core/error.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {
// Named, not anonymous: CircleDesign, declared in the header, holds records of these.
namespace diagnostics_fit {

// One sample as the fit sees it: the set-point, the measured position, the commanded
// velocity (central differences: the set-point is noise-free) and whether it lies within
// the window after a reversal of each axis (left out of that axis' fit, spikes there).
struct Walked {
  std::size_t pass = 0, i = 0, n = 0;
  Eigen::Vector2d cmd, meas, vel;
  bool skip[2] = {false, false};
  double fs_hz = 0.0;
  // Per axis: the set-point's columns from a CircleDesign (the 9 common ones, the backlash
  // as a step, then sin and cos per pitch); null: the model computes them.
  const double* cols[2] = {nullptr, nullptr};
};

// Normal equations of one axis, per pass, over the columns [common 9 | target | cyclic 2K],
// accumulated a block of rows at a time. A fit uses the cyclic columns of one pitch only:
// the products of two pitches' columns are never formed.
struct AxisGram {
  static constexpr std::size_t kTarget = 9, kCyc = 10;
  std::size_t width = 0;
  std::vector<Eigen::MatrixXd> m;  // per pass, lower triangle
  std::vector<std::size_t> rows;   // per pass
  Eigen::MatrixXd block;
  std::size_t fill = 0, fill_pass = 0;
  static constexpr std::size_t kBlock = 256;
  AxisGram(std::size_t n_pass, std::size_t pitches)
      : width(9 + 2 * pitches + 1),
        m(n_pass, Eigen::MatrixXd::Zero(9 + 2 * pitches + 1, 9 + 2 * pitches + 1)),
        rows(n_pass, 0) {
    block.resize(static_cast<Eigen::Index>(kBlock), static_cast<Eigen::Index>(width));
  }
  double* next_row(std::size_t pass) {
    if (fill > 0 && pass != fill_pass) flush();
    fill_pass = pass;
    ++rows[pass];
    return &block(static_cast<Eigen::Index>(fill++), 0);  // column-major: stride kBlock
  }
  // One sample's row: the common features, the target and n_cyc cyclic columns.
  void add_row(std::size_t pass, const double* common9, double target, const double* cyc, std::size_t n_cyc) {
    double* r = next_row(pass);
    const auto stride = static_cast<std::size_t>(kBlock);
    for (std::size_t j = 0; j < 9; ++j) r[j * stride] = common9[j];
    r[kTarget * stride] = target;
    for (std::size_t j = 0; j < n_cyc; ++j) r[(kCyc + j) * stride] = cyc[j];
    if (fill == kBlock) flush();
  }
  void flush() {
    if (fill == 0) return;
    const auto f = block.topRows(static_cast<Eigen::Index>(fill));
    auto& g = m[fill_pass];
    const auto head = static_cast<Eigen::Index>(kCyc), cyc = static_cast<Eigen::Index>(width) - head;
    g.topLeftCorner(head, head).selfadjointView<Eigen::Lower>().rankUpdate(f.leftCols(head).transpose());
    if (cyc > 0) {
      g.bottomLeftCorner(cyc, head).noalias() += f.rightCols(cyc).transpose() * f.leftCols(head);
      for (Eigen::Index k = 0; k < cyc; k += 2)
        g.block(head + k, head + k, 2, 2).noalias() +=
            f.middleCols(head + k, 2).transpose() * f.middleCols(head + k, 2);
    }
    fill = 0;
  }
  [[nodiscard]] double at(std::size_t pass, std::size_t r, std::size_t c) const {
    const auto& g = m[pass];
    return r >= c ? g(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c))
                  : g(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(r));
  }
};

}  // namespace diagnostics_fit

namespace {

using diagnostics_fit::AxisGram;
using diagnostics_fit::Walked;

using units::kUmPerMm;

int sgn(double v, double eps) { return v > eps ? 1 : (v < -eps ? -1 : 0); }

// Fixed columns of the per-axis model (after the per-pass drift polynomials).
enum Col { scale, square, lag, backlash, lateral, cyc_sin, cyc_cos, bow, n_cols };

// Replays the passes and hands each sample over once its velocity is known (one sample
// of lookahead), with the reversal masks; checks what the stored version checked.
template <class F>
void walk(PassReplay& replay, std::size_t window, F&& f) {
  const auto& passes = replay.passes();
  std::size_t cur = SIZE_MAX, i = 0, got = 0;
  Eigen::Vector2d prev_cmd, cmd, meas;
  int last[2] = {0, 0};
  std::size_t until[2] = {0, 0};
  auto emit = [&](const Eigen::Vector2d& ca, const Eigen::Vector2d& cb, std::size_t span) {
    Walked w;
    w.pass = cur, w.i = i, w.n = passes[cur].samples, w.cmd = cmd, w.meas = meas, w.fs_hz = passes[cur].fs_hz;
    w.vel = span > 0 ? Eigen::Vector2d((cb - ca) * (w.fs_hz / static_cast<double>(span))) : Eigen::Vector2d::Zero();
    for (int a = 0; a < 2; ++a) {
      const int s = sgn(w.vel[a], 1e-6);
      if (s != 0 && last[a] != 0 && s != last[a]) until[a] = std::max(until[a], i + window);
      if (s != 0) last[a] = s;
      w.skip[a] = i < until[a];
    }
    f(w);
    ++i;
  };
  auto close_pass = [&] {
    if (cur == SIZE_MAX || got == 0) return;
    // The last sample: its velocity from the one before it (or none, alone).
    if (got == 1)
      emit(cmd, cmd, 0);
    else
      emit(prev_cmd, cmd, 1);
  };
  replay.replay([&](std::size_t pass, const Eigen::Vector2d& c, const Eigen::Vector2d& m) {
    if (pass != cur) {
      close_pass();
      cur = pass, i = 0, got = 0, last[0] = last[1] = 0, until[0] = until[1] = 0;
    }
    if (!c.allFinite() || !m.allFinite())
      throw InputError("circle diagnostics: non-finite position at sample " + std::to_string(got));
    if (got >= 1) {  // the buffered sample's next one has come
      if (got == 1)
        emit(cmd, c, 1);
      else
        emit(prev_cmd, c, 2);
      prev_cmd = cmd;
    }
    cmd = c, meas = m;
    ++got;
  });
  close_pass();
}

// The rows of one axis' model for given settings (pitch, the play of the backlash operator).
struct AxisModel {
  int a = 0;  // 0 = x, 1 = y
  DiagnosticsOptions opt;
  std::vector<double> pitches_mm;    // the cyclic columns' pitches (one each: sin, cos)
  std::size_t cached_cyc_first = 0;  // where this model's pitches start among cached columns
  double play_mm = 0.0;              // > 0: the play operator; else the step −sgn(v)/2
  std::vector<int> d0;               // per pass: the first direction of motion of the axis
  // Per pass state of the play operator.
  double slide = 0.0;
  // Fills the common features [1, t, t², scale, square, lag, backlash, lateral, bow] and
  // the cyclic ones per pitch (sin, cos), and the target.
  void row(const Walked& w, double* common9, double* cyc, double& target) {
    if (const double* cached = w.cols[a]) {
      std::copy_n(cached, 9, common9);
      std::copy_n(cached + 9 + cached_cyc_first, 2 * pitches_mm.size(), cyc);
      common9[6] = backlash_column(w);
      target = w.meas[a] - w.cmd[a];
      return;
    }
    const int b = 1 - a;
    const double R = opt.radius_mm;
    const Eigen::Vector2d& c = w.cmd;
    const Eigen::Vector2d& v = w.vel;
    const double t = static_cast<double>(w.i) / static_cast<double>(w.n) - 0.5;  // scaled time
    common9[0] = 1.0, common9[1] = t, common9[2] = t * t;
    common9[3] = c[a] - opt.centre_mm[a];
    common9[4] = a == 0 ? -(c[1] - opt.centre_mm[1]) : 0.0;
    common9[5] = -v[a];
    common9[6] = backlash_column(w);
    common9[7] = 0.5 * sgn(v[b], 1e-6);
    const double u = (c[b] - opt.centre_mm[b]) / R;
    common9[8] = u * u;
    // sin, cos of 2π·x/p for every pitch; a pitch whose double is searched too takes the
    // double angle of that one's (2 sin cos, cos² − sin²): 4 sincos for the usual 13 pitches.
    for (std::size_t k = pitches_mm.size(); k-- > 0;) {
      if (half_of_[k] >= 0) {
        const double sn = cyc[2 * half_of_[k]], cs = cyc[2 * half_of_[k] + 1];
        cyc[2 * k] = 2.0 * sn * cs;
        cyc[2 * k + 1] = cs * cs - sn * sn;
      } else {
        const double arg = 2.0 * std::numbers::pi * c[a] / pitches_mm[k];
        cyc[2 * k] = std::sin(arg);
        cyc[2 * k + 1] = std::cos(arg);
      }
    }
    target = w.meas[a] - c[a];
  }
  // Backlash: the lost motion as the slide sees it. With a play estimate it is the play
  // operator's output (the slide waits until the motor has crossed the play, so the step
  // after a reversal takes time); without one, the step −sgn(v)/2. Called once per sample
  // in order (the operator's state runs through every sample of a pass).
  double backlash_column(const Walked& w) {
    if (!(play_mm > 0.0)) return -0.5 * sgn(w.vel[a], 1e-6);
    const double x = w.cmd[a];
    if (w.i == 0) slide = x - 0.5 * play_mm * d0[w.pass];  // play taken up in the first direction
    slide = std::clamp(slide, x - 0.5 * play_mm, x + 0.5 * play_mm);
    return (slide - x) / play_mm;
  }
  // For each pitch the index of its double among the pitches (−1: none); they ascend.
  void set_pitches(std::vector<double> p) {
    pitches_mm = std::move(p);
    half_of_.assign(pitches_mm.size(), -1);
    for (std::size_t k = 0; k < pitches_mm.size(); ++k)
      for (std::size_t j = k + 1; j < pitches_mm.size(); ++j)
        if (pitches_mm[j] == 2.0 * pitches_mm[k]) half_of_[k] = static_cast<int>(j);
  }

 private:
  std::vector<int> half_of_;
};

struct AxisFit {
  Eigen::VectorXd coef;     // fixed columns only (n_cols)
  Eigen::VectorXd x;        // every unknown (polynomials per pass, then the used fixed columns)
  std::vector<int> col_of;  // unknown index of each fixed column, −1 when not used
  std::size_t n_poly = 0;   // the polynomials' unknowns (x's first)
  double rms_mm = 0.0;
};

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

// The fit's residual at a sample (target − model), rows as AxisModel makes them.
double residual(const AxisFit& fit, const double* common9, const double* cyc, double target, std::size_t pass,
                double fixed_lag_s, double v_a) {
  const std::size_t n_poly = fit.n_poly;
  double model = 0.0;
  for (std::size_t j = 0; j < 3; ++j) model += fit.x(static_cast<Eigen::Index>(3 * pass + j)) * common9[j];
  const double fixed[n_cols] = {common9[3], common9[4], common9[5], common9[6], common9[7], cyc[0], cyc[1], common9[8]};
  for (int c = 0; c < n_cols; ++c)
    if (fit.col_of[static_cast<std::size_t>(c)] >= 0)
      model += fit.x(static_cast<Eigen::Index>(n_poly) + fit.col_of[static_cast<std::size_t>(c)]) * fixed[c];
  return target + fixed_lag_s * v_a - model;
}

// Stored passes, replayed from memory.
class StoredPasses final : public PassReplay {
 public:
  explicit StoredPasses(const std::vector<CirclePass>& p) : p_(p) {
    for (const auto& x : p) info_.push_back({x.direction, x.fs_hz, x.cmd_mm.size()});
  }
  [[nodiscard]] const std::vector<Pass>& passes() const override { return info_; }
  void replay(const std::function<void(std::size_t, const Eigen::Vector2d&, const Eigen::Vector2d&)>& f) override {
    for (std::size_t k = 0; k < p_.size(); ++k)
      for (std::size_t i = 0; i < p_[k].cmd_mm.size(); ++i) f(k, p_[k].cmd_mm[i], p_[k].meas_mm[i]);
  }

 private:
  const std::vector<CirclePass>& p_;
  std::vector<Pass> info_;
};

// Every q-th sample of each pass, from its first: what the fits read. Their columns are
// smooth in time and the path's error is low-pass (integrated noise, bias walk), so a
// faster sampling adds rows, not information; the uncertainty's draws fit at this rate
// too (figure_uncertainty.cpp). The residuals' spikes are searched at the full rate.
class DecimatedPasses final : public PassReplay {
 public:
  DecimatedPasses(PassReplay& full, std::size_t q) : full_(full), q_(std::max<std::size_t>(1, q)) {
    for (const Pass& p : full.passes())
      info_.push_back({p.direction, p.fs_hz / static_cast<double>(q_), (p.samples + q_ - 1) / q_});
  }
  [[nodiscard]] const std::vector<Pass>& passes() const override { return info_; }
  void replay(const std::function<void(std::size_t, const Eigen::Vector2d&, const Eigen::Vector2d&)>& f) override {
    std::size_t cur = SIZE_MAX, i = 0;
    full_.replay([&](std::size_t pass, const Eigen::Vector2d& c, const Eigen::Vector2d& m) {
      if (pass != cur) cur = pass, i = 0;
      if (i++ % q_ == 0) f(pass, c, m);
    });
  }

 private:
  PassReplay& full_;
  std::size_t q_;
  std::vector<Pass> info_;
};

// The fits' rate (at least this; the passes' own when slower).
constexpr double kFitRateHz = 1000.0;

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

// Every fixed column, and every one but the lag (a single-direction x fit borrows y's).
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

// First replay: the normal equations of both axes over every pitch, outside the reversal
// windows; records each axis' first direction of motion per pass into its model.
std::vector<AxisGram> accumulate_every_pitch(PassReplay& replay, std::size_t window, std::array<AxisModel, 2>& model) {
  const std::size_t n_pitch = model[0].pitches_mm.size();
  std::vector<AxisGram> gram;
  for (int a = 0; a < 2; ++a) gram.emplace_back(replay.passes().size(), n_pitch);
  std::vector<double> cyc(2 * n_pitch);
  walk(replay, window, [&model, &gram, &cyc](const Walked& w) {
    for (int a = 0; a < 2; ++a) {
      if (model[a].d0[w.pass] == 0) model[a].d0[w.pass] = sgn(w.vel[a], 1e-6);
      if (w.skip[a]) continue;
      double c9[9], target = 0.0;
      model[a].row(w, c9, cyc.data(), target);
      gram[a].add_row(w.pass, c9, target, cyc.data(), cyc.size());
    }
  });
  for (auto& g : gram) g.flush();
  return gram;
}

// Second replay: the normal equations of both axes for the one pitch the models hold now.
std::vector<AxisGram> accumulate_best_pitch(PassReplay& replay, std::size_t window, std::array<AxisModel, 2>& model) {
  std::vector<AxisGram> gram;
  for (int a = 0; a < 2; ++a) gram.emplace_back(replay.passes().size(), 1);
  walk(replay, window, [&model, &gram](const Walked& w) {
    for (int a = 0; a < 2; ++a) {
      double c9[9], cyc[2], target = 0.0;
      model[a].row(w, c9, cyc, target);  // every sample: the play operator runs through the skipped ones too
      if (w.skip[a]) continue;
      gram[a].add_row(w.pass, c9, target, cyc, 2);
    }
  });
  for (auto& g : gram) g.flush();
  return gram;
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

struct AxisFits {
  std::array<AxisFit, 2> axis;
  double fixed_lag_x_s = 0.0;  // moved to x's target (one direction only): y's lag
};

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
    d.notes.push_back("one direction only: servo mismatch cannot be separated from squareness; equal lags assumed");
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

// What the final fits leave, summed over the third replay.
struct ResidualSums {
  double spike_sum[2] = {0.0, 0.0};  // signed reversal spikes (positive: lagging)
  int spike_count[2] = {0, 0};
  double ss_rad = 0.0, ss_axis[2] = {0.0, 0.0};  // outside every reversal window
  std::size_t n = 0;
  double ss_fit[2] = {0.0, 0.0};  // outside the axis' own reversal windows
  std::size_t n_fit[2] = {0, 0};
};

// The third replay's per-sample work. Reversal spikes (the mean signed peak of the residual
// in the window after each reversal of the axis, the window within the pass); what the
// model leaves (RMS over the samples outside the reversal windows): radially the vibration
// class, per axis the stick-slip class.
class ResidualMeter {
 public:
  ResidualMeter(std::array<AxisModel, 2>& model, const AxisFits& fits, const Eigen::Vector2d& centre_mm,
                std::size_t window)
      : model_(model), fits_(fits), centre_mm_(centre_mm), window_(window) {}

  void add(const Walked& w) {
    if (w.pass != pass_now_) pass_now_ = w.pass, last_[0] = last_[1] = 0, open_[0].clear(), open_[1].clear();
    double r[2];
    for (int a = 0; a < 2; ++a) {
      double c9[9], cyc[2], target = 0.0;
      model_[a].row(w, c9, cyc, target);
      r[a] = residual(fits_.axis[a], c9, cyc, target, w.pass, a == 0 ? fits_.fixed_lag_x_s : 0.0, w.vel[a]);
      if (!w.skip[a]) sums_.ss_fit[a] += r[a] * r[a], ++sums_.n_fit[a];
      track_spikes(a, w, r[a]);
    }
    if (w.skip[0] || w.skip[1]) return;
    const Eigen::Vector2d res(r[0], r[1]);
    Eigen::Vector2d radial = w.cmd - centre_mm_;
    if (radial.norm() <= 0.0) return;
    radial.normalize();
    sums_.ss_rad += std::pow(res.dot(radial), 2);
    sums_.ss_axis[0] += res[0] * res[0], sums_.ss_axis[1] += res[1] * res[1];
    ++sums_.n;
  }
  [[nodiscard]] const ResidualSums& sums() const { return sums_; }

 private:
  struct Spike {
    std::size_t end;  // window end (exclusive), within the pass
    int s;
    double peak = 0.0;
  };
  // A reversal opens a window when the whole window lies within the pass; a window closes
  // with its peak residual.
  void track_spikes(int a, const Walked& w, double r) {
    const int s = sgn(w.vel[a], 1e-6);
    if (s != 0 && last_[a] != 0 && s != last_[a] && w.i + window_ <= w.n) open_[a].push_back({w.i + window_, s});
    if (s != 0) last_[a] = s;
    for (auto it = open_[a].begin(); it != open_[a].end();) {
      if (std::abs(r) > std::abs(it->peak)) it->peak = r;
      if (w.i + 1 == it->end) {
        // Positive when the axis lags behind its new direction (friction holds it at the
        // reversal, the usual reversal spike); an overshoot is negative.
        sums_.spike_sum[a] -= it->peak * it->s;
        ++sums_.spike_count[a];
        it = open_[a].erase(it);
      } else {
        ++it;
      }
    }
  }

  std::array<AxisModel, 2>& model_;
  const AxisFits& fits_;
  Eigen::Vector2d centre_mm_;
  std::size_t window_;
  std::array<std::vector<Spike>, 2> open_;
  int last_[2] = {0, 0};
  std::size_t pass_now_ = SIZE_MAX;
  ResidualSums sums_;
};

// Reversal spikes, the fast residual (stick-slip at creep feed, else vibration) and the fit's RMS.
void report_residuals(const ResidualSums& s, const DiagnosticsOptions& opt, CircleDiagnostics& d) {
  d.reversal_spike_x_um = s.spike_count[0] > 0 ? s.spike_sum[0] / s.spike_count[0] * kUmPerMm : 0.0;
  d.reversal_spike_y_um = s.spike_count[1] > 0 ? s.spike_sum[1] / s.spike_count[1] * kUmPerMm : 0.0;
  if (s.n > 0) {
    if (opt.feed_mm_min > 0.0 && opt.feed_mm_min <= opt.creep_feed_mm_min) {
      // Creep feed: the fast residual of each axis is its slide sticking and slipping — a
      // sawtooth (or triangle) between 0 and the lag A, whose RMS is A/(2√3). Its mean lag
      // A/2 against the direction of motion reads as backlash A.
      const double ax = std::sqrt(s.ss_axis[0] / static_cast<double>(s.n)),
                   ay = std::sqrt(s.ss_axis[1] / static_cast<double>(s.n));
      d.stick_slip_um = 2.0 * std::sqrt(3.0) * std::max(ax, ay) * kUmPerMm;
      d.notes.push_back(
          "creep feed: the fast residual is reported as stick-slip (its mean lag also reads as backlash)");
    } else {
      d.vibration_um = std::sqrt(s.ss_rad / static_cast<double>(s.n)) * kUmPerMm;
    }
  }
  const double rms_x = s.n_fit[0] > 0 ? std::sqrt(s.ss_fit[0] / static_cast<double>(s.n_fit[0])) : 0.0;
  const double rms_y = s.n_fit[1] > 0 ? std::sqrt(s.ss_fit[1] / static_cast<double>(s.n_fit[1])) : 0.0;
  d.residual_rms_um = std::hypot(rms_x, rms_y) * kUmPerMm;
}

// The measured sample of a design's record (q: the record's rate divisor of the passes').
const Eigen::Vector2d& measured(const std::vector<CirclePass>& passes, const Walked& r, std::size_t q) {
  const Eigen::Vector2d& m = passes[r.pass].meas_mm[r.i * q];
  if (!m.allFinite()) throw InputError("circle diagnostics: non-finite position at sample " + std::to_string(r.i * q));
  return m;
}

}  // namespace

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
  // Throws unless `p` are the passes this was made of.
  void check(const std::vector<CirclePass>& p) const {
    bool same = p.size() == passes.size();
    for (std::size_t k = 0; same && k < p.size(); ++k)
      same = p[k].direction == passes[k].direction && p[k].fs_hz == passes[k].fs_hz &&
             p[k].cmd_mm.size() == passes[k].samples && p[k].meas_mm.size() == passes[k].samples;
    for (std::size_t k = 0; same && k < fit.size(); k += std::max<std::size_t>(1, fit.size() / 16))
      same = fit[k].cmd == p[fit[k].pass].cmd_mm[fit[k].i * q];
    if (!same) throw InputError("circle diagnostics: the design was made of another set-point");
  }
};

namespace {

// The set-point's passes, each measured position the commanded one (a design reads no
// measurement).
class SetPointPasses final : public PassReplay {
 public:
  explicit SetPointPasses(const std::vector<CirclePass>& p) : p_(p) {
    for (const auto& x : p) info_.push_back({x.direction, x.fs_hz, x.cmd_mm.size()});
  }
  [[nodiscard]] const std::vector<Pass>& passes() const override { return info_; }
  void replay(const std::function<void(std::size_t, const Eigen::Vector2d&, const Eigen::Vector2d&)>& f) override {
    for (std::size_t k = 0; k < p_.size(); ++k)
      for (const Eigen::Vector2d& c : p_[k].cmd_mm) f(k, c, c);
  }

 private:
  const std::vector<CirclePass>& p_;
  std::vector<Pass> info_;
};

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

CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& options) {
  for (const auto& p : passes)
    if (p.cmd_mm.size() != p.meas_mm.size())
      throw InputError("circle diagnostics: commanded and measured traces differ in length");
  StoredPasses replay(passes);
  return diagnose_circle(replay, options);
}

CircleDiagnostics diagnose_circle(PassReplay& replay, const DiagnosticsOptions& opt) {
  const auto& passes = replay.passes();
  const bool both_directions = check_passes(passes, opt);
  const auto window = static_cast<std::size_t>(std::lround(opt.spike_window_s * passes.front().fs_hz));
  const std::vector<double> pitches = candidate_pitches(opt);
  DecimatedPasses fit_replay(replay,
                             static_cast<std::size_t>(std::max(1.0, std::floor(passes.front().fs_hz / kFitRateHz))));
  const auto fit_window = static_cast<std::size_t>(std::lround(opt.spike_window_s * fit_replay.passes().front().fs_hz));

  // First replay: every pitch with the backlash as a step, both axes; each axis' first
  // direction of motion per pass (the play operator starts from it).
  std::array<AxisModel, 2> model = step_models(opt, pitches, passes.size());
  const std::vector<AxisGram> gram = accumulate_every_pitch(fit_replay, fit_window, model);
  const std::size_t best = search_pitch(gram, pitches.size());
  // Round one: the backlash as a step (what the pitch search fitted).
  const AxisFits round_one = fit_axes(gram, best, both_directions);

  // Second replay, round two: the play operator of the play just found (a sharp step
  // would leave the play's crossing time as a false reversal spike).
  for (std::size_t a = 0; a < 2; ++a) {
    model[a].set_pitches({pitches[best]});
    model[a].play_mm = std::max(0.0, round_one.axis[a].coef(backlash));
  }
  const AxisFits fits = fit_axes(accumulate_best_pitch(fit_replay, fit_window, model), 0, both_directions);

  CircleDiagnostics d;
  report_fit(fits, pitches[best], both_directions, d);
  // Third replay: the residuals of the final fits.
  ResidualMeter meter(model, fits, opt.centre_mm, window);
  walk(replay, window, [&meter](const Walked& w) { meter.add(w); });
  report_residuals(meter.sums(), opt, d);
  return d;
}

std::shared_ptr<const CircleDesign> circle_design(const std::vector<CirclePass>& passes,
                                                  const DiagnosticsOptions& options) {
  for (const auto& p : passes)
    if (p.cmd_mm.size() != p.meas_mm.size())
      throw InputError("circle diagnostics: commanded and measured traces differ in length");
  SetPointPasses replay(passes);
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
  for (std::size_t k = 0; k < d->fit.size(); ++k) {
    const Walked& r = d->fit[k];
    for (std::size_t a = 0; a < 2; ++a) {
      if (d->d0[a].empty()) d->d0[a].assign(passes.size(), 0);
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
  design.check(passes);
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
