#pragma once
// The circle diagnostics' fit (circle_diagnostics.hpp): one sample as the fit sees it, the
// per-axis model and its normal equations, the least squares and the residuals. Shared by
// the fit over replayed passes (circle_diagnostics.cpp) and the fit from a set-point's
// design (circle_design.cpp); not for use outside dsp/eval.
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_diagnostics.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

namespace eical::dsp::eval::diagnostics_fit {

inline int sgn(double v, double eps) { return v > eps ? 1 : (v < -eps ? -1 : 0); }

// Fixed columns of the per-axis model (after the per-pass drift polynomials).
enum Col { scale, square, lag, backlash, lateral, cyc_sin, cyc_cos, bow, n_cols };

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
AxisFit solve_axis(const AxisGram& g, std::size_t k, const std::array<bool, n_cols>& use, double fixed_lag_s);

// The fit's residual at a sample (target − model), rows as AxisModel makes them.
inline double residual(const AxisFit& fit, const double* common9, const double* cyc, double target, std::size_t pass,
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

// Stored passes, replayed from memory; kSetPointOnly: each measured position the
// commanded one.
class StoredPasses final : public PassReplay {
 public:
  static constexpr bool kSetPointOnly = true;
  explicit StoredPasses(const std::vector<CirclePass>& p, bool cmd_only = false) : p_(p), cmd_only_(cmd_only) {
    for (const auto& x : p) info_.push_back({x.direction, x.fs_hz, x.cmd_mm.size()});
  }
  [[nodiscard]] const std::vector<Pass>& passes() const override { return info_; }
  void replay(const std::function<void(std::size_t, const Eigen::Vector2d&, const Eigen::Vector2d&)>& f) override {
    for (std::size_t k = 0; k < p_.size(); ++k)
      for (std::size_t i = 0; i < p_[k].cmd_mm.size(); ++i)
        f(k, p_[k].cmd_mm[i], (cmd_only_ ? p_[k].cmd_mm : p_[k].meas_mm)[i]);
  }

 private:
  const std::vector<CirclePass>& p_;
  bool cmd_only_;
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
bool check_passes(const std::vector<PassReplay::Pass>& passes, const DiagnosticsOptions& opt);

// The pitches searched for the cyclic error. A pitch is identifiable only with at least two
// periods over the diameter; longer ones are collinear with scale, offset and bow.
std::vector<double> candidate_pitches(const DiagnosticsOptions& opt);

// Every fixed column, and every one but the lag (a single-direction x fit borrows y's).
std::array<bool, n_cols> every_column();
std::array<bool, n_cols> every_column_but_lag();

// Both axes' models with the backlash as a step, searching `pitches`.
std::array<AxisModel, 2> step_models(const DiagnosticsOptions& opt, const std::vector<double>& pitches,
                                     std::size_t n_pass);

// The pitch (index) whose fit leaves the least, both axes.
std::size_t search_pitch(const std::vector<AxisGram>& gram, std::size_t n_pitch);

struct AxisFits {
  std::array<AxisFit, 2> axis;
  double fixed_lag_x_s = 0.0;  // moved to x's target (one direction only): y's lag
};

// Both axes at pitch k. Y first: its lag is identifiable from one direction (v_y follows
// cos θ, squareness sits in the x equation only), and a single-direction x fit borrows it.
AxisFits fit_axes(const std::vector<AxisGram>& gram, std::size_t k, bool both_directions);

// The fitted machine errors into the diagnostics, in ballbar conventions.
void report_fit(const AxisFits& fits, double pitch_mm, bool both_directions, CircleDiagnostics& d);

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
void report_residuals(const ResidualSums& s, const DiagnosticsOptions& opt, CircleDiagnostics& d);

}  // namespace eical::dsp::eval::diagnostics_fit
