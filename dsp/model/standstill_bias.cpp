#include "dsp/model/standstill_bias.hpp"

#include "dsp/core/chi2.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::dsp::model {
namespace {

constexpr double kSettleS = 0.2;  // the position loop's creep (1/kv ≈ 30 ms) is gone
constexpr double kTailS = 0.02;   // the next move's first jerk may sit in the DAQ filter
constexpr double kMinLateS = 0.08;
constexpr double kWalkUgPerRtS = 0.3;    // data-sheet bias walk per sensor: tolerated
constexpr double kMaxTempCoeff = 900.0;  // µg/°C of head − table: two sensors' 450 (bias, and scale × 1 g)
constexpr double kTempPrior = 300.0;     // µg/°C: the prior σ of each coefficient
constexpr int kBatches = 8;
constexpr double kBlockS = 0.1;  // a still-ringing mode of 10 Hz or more shows in its spread
constexpr double kRingingFactor = 1.5;

// Weight of sample i of n in a Hann-weighted mean.
double hann_weight(std::size_t i, std::size_t n) {
  return 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * (static_cast<double>(i) + 0.5) / static_cast<double>(n));
}

// Generalised least squares of y on the columns of x under the covariance whose Cholesky
// factor is `l`; returns χ² of the residual.
// With prior_sigma > 0 each coefficient has a zero-mean Gaussian prior of that σ (its
// penalty is part of the χ²): collinear regressors then share the fit plausibly.
double gls_chi2(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Eigen::MatrixXd& l,
                Eigen::VectorXd* beta = nullptr, double prior_sigma = 0.0) {
  const Eigen::VectorXd yw = l.triangularView<Eigen::Lower>().solve(y);
  if (x.cols() == 0) return yw.squaredNorm();
  Eigen::MatrixXd xw = l.triangularView<Eigen::Lower>().solve(x);
  Eigen::VectorXd ya = yw;
  if (prior_sigma > 0.0) {
    xw.conservativeResize(xw.rows() + x.cols(), Eigen::NoChange);
    xw.bottomRows(x.cols()) = Eigen::MatrixXd::Identity(x.cols(), x.cols()) / prior_sigma;
    ya.conservativeResize(ya.size() + x.cols());
    ya.tail(x.cols()).setZero();
  }
  const Eigen::VectorXd b = xw.colPivHouseholderQr().solve(ya);
  if (beta) *beta = b;
  return (ya - xw * b).squaredNorm();
}

// The raw signals every window reads, and what its figures are scaled by.
struct WindowInputs {
  const RunResiduals& run;
  const Measurement& m;
  double fs_hz, g_ug;
  double noise_rel;              // head − table's white noise, µg/√Hz (data sheet)
  std::int64_t block;            // samples of one spread block (kBlockS)
  Eigen::Vector3d ref_offset{};  // the Hann-weighted rest before the motion, less the pipeline's
};

// The spread of head − table over one block from `from`: a mode still ringing shows in it.
double block_spread(const Measurement& m, std::int64_t from, std::int64_t block) {
  Eigen::Vector3d s1 = Eigen::Vector3d::Zero(), s2 = Eigen::Vector3d::Zero();
  for (std::int64_t i = from; i < from + block; ++i) {
    const Eigen::Vector3d rel =
        m.raw.head_mps2[static_cast<std::size_t>(i)] - m.raw.table_mps2[static_cast<std::size_t>(i)];
    s1 += rel, s2 += rel.cwiseAbs2();
  }
  const auto nb = static_cast<double>(block);
  return std::sqrt(std::max(0.0, (s2 - s1.cwiseAbs2() / nb).sum() / nb));
}

// The reference, Hann-weighted as the windows are: the pipeline's plain mean of the rest
// before the motion carries a tone's leakage that every standstill would then show.
Eigen::Vector3d rest_reference_offset(const Measurement& m) {
  Eigen::Vector3d ref_offset = Eigen::Vector3d::Zero();
  if (const auto& rest = m.raw.rest_rel_mps2; rest.size() > 10) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double wsum = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i) {
      const double hann = hann_weight(i, rest.size());
      sum += hann * rest[i], wsum += hann;
    }
    ref_offset = sum / wsum - m.rest_bias_rel_mps2;
  }
  return ref_offset;
}

// The late part of each rest window (raw sample spans [a, b]) and the quiet level of the
// run's rest: the 20th percentile of the spread of all their blocks, tones that never stop
// included.
struct LateSpans {
  std::vector<std::pair<std::int64_t, std::int64_t>> spans;
  double quiet = 0.0;
};

LateSpans late_spans(const WindowInputs& in) {
  const Measurement& m = in.m;
  const double fs = in.fs_hz;
  const std::int64_t i0 = m.sample_index.front();
  const auto n_raw = static_cast<std::int64_t>(std::min(m.raw.table_mps2.size(), m.raw.head_mps2.size()));
  LateSpans out;
  std::vector<double> spreads;
  for (const auto& w : m.supports.rest_windows) {
    const std::int64_t a = w.first_index - i0 + static_cast<std::int64_t>(kSettleS * fs);
    const std::int64_t b =
        std::min<std::int64_t>(w.last_index - i0 - static_cast<std::int64_t>(kTailS * fs), n_raw - 1);
    if (a < 0 || b - a < static_cast<std::int64_t>(kMinLateS * fs)) continue;
    out.spans.emplace_back(a, b);
    for (std::int64_t c = a; c + in.block <= b; c += in.block) spreads.push_back(block_spread(m, c, in.block));
  }
  if (!spreads.empty()) {
    auto q = spreads.begin() + static_cast<std::ptrdiff_t>(spreads.size() / 5);
    std::nth_element(spreads.begin(), q, spreads.end());
    out.quiet = *q;
  }
  return out;
}

// One standstill's late part [a, b] (opened: where its rest began): the change of its mean
// against the rest before the motion, its standard error, each sensor's own mean.
StandstillBias::Window measure_window(const WindowInputs& in, std::int64_t a, std::int64_t b, std::int64_t opened) {
  const RunResiduals& r = in.run;
  const Measurement& m = in.m;
  const double fs = in.fs_hz, g_ug = in.g_ug;
  StandstillBias::Window win;
  win.t_s = 0.5 * static_cast<double>(a + b) / fs;
  win.settle_s = static_cast<double>(a - opened) / fs, win.length_s = static_cast<double>(b - a + 1) / fs;
  const auto ds = static_cast<Eigen::Index>(
      std::clamp(std::lround(win.t_s / std::max(r.dt_s, 1e-9)), 0L, static_cast<long>(r.n) - 1));
  for (int s = 0; s < 2; ++s) win.temp_c[s] = r.temp_c(ds, s);
  const std::int64_t len = (b - a + 1) / kBatches;
  Eigen::Vector3d batch[kBatches], plain = Eigen::Vector3d::Zero(), mean = Eigen::Vector3d::Zero(),
                                   own[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  // The window's mean is Hann-weighted: a machine's tones (a spindle, a structural mode
  // still ringing) leak into a plain mean by 1/(2πfT), into a tapered one by ~1/(2πfT)³.
  // White noise costs the taper a factor 1.5 in variance.
  const std::int64_t n_used = len * kBatches;
  double wsum = 0.0;
  for (int k = 0; k < kBatches; ++k) {
    batch[k].setZero();
    for (std::int64_t i = a + k * len; i < a + (k + 1) * len; ++i) {
      const auto u = static_cast<std::size_t>(i);
      const Eigen::Vector3d rel = m.raw.head_mps2[u] - m.raw.table_mps2[u];
      const double hann = hann_weight(static_cast<std::size_t>(i - a), static_cast<std::size_t>(n_used));
      batch[k] += rel, mean += hann * rel, wsum += hann;
      own[0] += m.raw.table_mps2[u], own[1] += m.raw.head_mps2[u];
    }
    batch[k] /= static_cast<double>(len);
    plain += batch[k] / kBatches;
  }
  mean = mean / wsum - in.ref_offset;
  Eigen::Vector3d var = Eigen::Vector3d::Zero();
  for (const auto& bm : batch) var += (bm - plain).cwiseAbs2();
  var *= 1.5 / (static_cast<double>(kBatches - 1) * kBatches);  // of the tapered mean
  // Not below the white noise of the data sheet (a batch estimate can come out small).
  const double white = in.noise_rel * std::sqrt(1.5 * fs / static_cast<double>(n_used));
  for (int ax = 0; ax < 3; ++ax) {
    win.bias_ug[ax] = mean[ax] / g_ug;
    win.sigma_ug[ax] =
        std::sqrt(std::max(var[ax] / (g_ug * g_ug), white * white) + 2.0 * kWalkUgPerRtS * kWalkUgPerRtS * win.t_s);
    for (int s = 0; s < 2; ++s) win.sensor_ug[s][ax] = own[s][ax] / static_cast<double>(len * kBatches) / g_ug;
  }
  return win;
}

// Every late span that is long enough once a mode still ringing in it has stopped: a
// structural mode between head and table rings on after a move and biases the mean of the
// standstill that follows, so each window begins where the relative signal's spread (in
// blocks of kBlockS) is back to the quiet level of the run's rest.
std::vector<StandstillBias::Window> measure_windows(const WindowInputs& in, const LateSpans& late) {
  const double fs = in.fs_hz;
  std::vector<StandstillBias::Window> windows;
  for (auto [a, b] : late.spans) {
    const std::int64_t opened = a - static_cast<std::int64_t>(kSettleS * fs);
    while (a + in.block <= b && block_spread(in.m, a, in.block) > kRingingFactor * late.quiet) a += in.block;
    if (b - a < static_cast<std::int64_t>(kMinLateS * fs)) continue;
    windows.push_back(measure_window(in, a, b, opened));
  }
  return windows;
}

// Per axis the standstill means and the Cholesky factor of their covariance.
struct AxisSeries {
  Eigen::MatrixXd chol[3];
  Eigen::VectorXd series[3];
};

// Every standstill is compared with the same rest window: its own error (its length,
// white noise with the DAQ filter's correlation, Hann-weighted) is common to all of them.
// χ² and dof of "no change" into `out`.
AxisSeries compare_with_rest(const WindowInputs& in, StandstillBias& out) {
  const auto k = static_cast<Eigen::Index>(out.windows.size());
  const double rest_n = static_cast<double>(std::max<std::size_t>(in.m.rest_window_samples, 1));
  const double ref = 1.5 * in.noise_rel * std::sqrt(1.5 * in.fs_hz / rest_n);  // 1.5 in variance: the taper
  AxisSeries as;
  for (int ax = 0; ax < 3; ++ax) {
    Eigen::MatrixXd c = Eigen::MatrixXd::Constant(k, k, ref * ref);
    as.series[ax].resize(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      const auto& w = out.windows[static_cast<std::size_t>(i)];
      c(i, i) += w.sigma_ug[ax] * w.sigma_ug[ax];
      as.series[ax][i] = w.bias_ug[ax];
    }
    as.chol[ax] = c.llt().matrixL();
    out.chi2 += gls_chi2(Eigen::MatrixXd(k, 0), as.series[ax], as.chol[ax]);
    out.dof += static_cast<int>(k);
  }
  return as;
}

// The largest change (its axis, the sensor whose own mean moved more), the largest case
// temperature change, and whether the χ² says the bias changed.
void find_largest_change(StandstillBias& out) {
  for (const auto& w : out.windows) {
    for (int s = 0; s < 2; ++s) out.temperature_change_c = std::max(out.temperature_change_c, std::abs(w.temp_c[s]));
    for (int ax = 0; ax < 3; ++ax)
      if (std::abs(w.bias_ug[ax]) > out.largest_change_ug) {
        out.largest_change_ug = std::abs(w.bias_ug[ax]), out.axis = ax;
        out.sensor = std::abs(w.sensor_ug[1][ax]) >= std::abs(w.sensor_ug[0][ax]) ? 1 : 0;
      }
  }
  out.changed = out.chi2 > chi2_quantile(out.dof, 5.0) && out.largest_change_ug > 1.0;
}

// The patterns' regressors per window: drift (time), steps (offset and alternating sign),
// temperature (columns head, −table).
struct PatternRegressors {
  Eigen::MatrixXd drift, steps, temp;
};

PatternRegressors pattern_regressors(const std::vector<StandstillBias::Window>& windows) {
  const auto k = static_cast<Eigen::Index>(windows.size());
  PatternRegressors x{Eigen::MatrixXd(k, 1), Eigen::MatrixXd(k, 2), Eigen::MatrixXd(k, 2)};
  Eigen::MatrixXd &xd = x.drift, &xs = x.steps, &xt = x.temp;
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto& w = windows[static_cast<std::size_t>(i)];
    xd(i, 0) = w.t_s, xs(i, 0) = 1.0, xs(i, 1) = i % 2 == 0 ? 1.0 : -1.0, xt(i, 0) = w.temp_c[1],
          xt(i, 1) = -w.temp_c[0];
  }
  // Case temperatures that rise alike (correlation above 0.98 over the run): one
  // coefficient on their mean, the difference of the two sensors' (two would split it
  // arbitrarily).
  {
    const double n0 = xt.col(0).norm(), n1 = xt.col(1).norm();
    const double corr = n0 > 0.0 && n1 > 0.0 ? std::abs(xt.col(0).dot(xt.col(1))) / (n0 * n1) : 1.0;
    if (corr > 0.98) xt = (0.5 * (xt.col(0) - xt.col(1))).eval();
  }
  return x;
}

// Each pattern's BIC summed over the axes, and the largest temperature coefficient fitted.
struct PatternScores {
  double bic_drift = 0.0, bic_steps = 0.0, bic_temp = 0.0;
  double temp_coeff_max = 0.0;
};

// The sizes of the patterns on the axis with the largest change: drift, step, and the
// temperature coefficient with the sensor it belongs to.
void take_pattern_sizes(const Eigen::VectorXd& bd, const Eigen::VectorXd& bs, const Eigen::VectorXd& bt,
                        StandstillBias& out) {
  out.drift_ug_per_s = bd[0];
  if (bs.size() == 2) out.step_ug = 2.0 * bs[1];
  // Columns (head, −table): each sensor's own coefficient; one column (the mean of the
  // two): head minus table's, given to the sensor whose own mean moved more.
  if (bt.size() > 1) {
    const int col = std::abs(bt[1]) > std::abs(bt[0]) ? 1 : 0;
    out.temp_coeff_ug_per_c = bt[col], out.temp_coeff_sensor = col == 0 ? 1 : 0;
  } else if (bt.size() == 1) {
    out.temp_coeff_sensor = out.sensor < 0 ? 1 : out.sensor;
    out.temp_coeff_ug_per_c = out.temp_coeff_sensor == 1 ? bt[0] : -bt[0];
  }
}

// Which pattern: per axis its own parameters, χ² summed, BIC with the window count. The
// temperature enters with both sensors' case temperatures (each its own coefficient).
PatternScores fit_patterns(const AxisSeries& as, double ln_n, StandstillBias& out) {
  const auto k = static_cast<Eigen::Index>(out.windows.size());
  const PatternRegressors x = pattern_regressors(out.windows);
  const Eigen::MatrixXd& xt = x.temp;
  PatternScores sc;
  for (int ax = 0; ax < 3; ++ax) {
    const Eigen::VectorXd& y = as.series[ax];
    Eigen::VectorXd bd, bs, bt;
    sc.bic_drift += gls_chi2(x.drift, y, as.chol[ax], &bd) + ln_n;
    sc.bic_steps += k >= 3 ? gls_chi2(x.steps, y, as.chol[ax], &bs) + 2.0 * ln_n : 1e300;
    const bool warm = xt.cwiseAbs().maxCoeff() > 0.0 && k > xt.cols();
    // Each sensor's coefficient (bias, and on the axis bearing gravity its scale's) with a
    // prior of what a sensor can have: case temperatures that rise alike share the fit.
    sc.bic_temp += warm ? gls_chi2(xt, y, as.chol[ax], &bt, kTempPrior) + static_cast<double>(xt.cols()) * ln_n : 1e300;
    if (bt.size() > 0) sc.temp_coeff_max = std::max(sc.temp_coeff_max, bt.cwiseAbs().maxCoeff());
    if (ax == out.axis) take_pattern_sizes(bd, bs, bt, out);
  }
  return sc;
}

// The pattern the scores name, and whether one shows a change the χ² alone did not.
void choose_pattern(const PatternScores& sc, double ln_n, StandstillBias& out) {
  bool temp_plausible = out.temperature_change_c > 0.05;
  if (sc.temp_coeff_max > kMaxTempCoeff) temp_plausible = false;
  // A pattern can show a change the omnibus χ² dilutes: its likelihood ratio against "no
  // change", BIC-penalised, counts as well.
  const double bic_best = std::min({sc.bic_drift, sc.bic_steps, temp_plausible ? sc.bic_temp : 1e300});
  if (out.chi2 - bic_best > 10.0 && out.largest_change_ug > 1.0) out.changed = true;
  // The case temperature is a measured cause: it wins unless a pattern in time fits clearly better.
  if (temp_plausible && sc.bic_temp <= sc.bic_drift + 2.0 && sc.bic_temp <= sc.bic_steps + 2.0)
    out.pattern = "temperature";
  else if (std::min(sc.bic_drift, sc.bic_steps) < out.chi2 - 2.0 * ln_n)
    out.pattern = sc.bic_steps < sc.bic_drift ? "steps" : "drift";
  else
    out.pattern = "walk";
}

std::string describe_standstills(const StandstillBias& out) {
  static const char* const kSensor[2] = {"table", "head"};
  static const char* const kAx[3] = {"x", "y", "z"};
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "head - table at %d standstills differs from the rest before the motion by up to %.2f ug (%s, mostly "
                "the %s; chi2 %.0f for %d dof); "
                "pattern: %s (drift %.3f ug/s, steps %.2f ug, %.1f ug/degC over %.2f degC)",
                static_cast<int>(out.windows.size()), out.largest_change_ug, out.axis >= 0 ? kAx[out.axis] : "-",
                out.sensor >= 0 ? kSensor[out.sensor] : "-", out.chi2, out.dof, out.pattern.c_str(), out.drift_ug_per_s,
                out.step_ug, out.temp_coeff_ug_per_c, out.temperature_change_c);
  return buf;
}

}  // namespace

StandstillBias standstill_bias(const RunResiduals& run) {
  StandstillBias out;
  const Measurement& m = run.measurement;
  if (m.sample_index.empty() || m.raw.table_mps2.empty()) return out;
  const WindowInputs in{
      .run = run,
      .m = m,
      .fs_hz = m.fs_hz,
      .g_ug = run.meta.site.g_mps2 * 1e-6,
      .noise_rel = std::hypot(run.meta.sensors[0].noise_ug_per_rthz, run.meta.sensors[1].noise_ug_per_rthz),
      .block = static_cast<std::int64_t>(kBlockS * m.fs_hz),
      .ref_offset = rest_reference_offset(m)};
  out.windows = measure_windows(in, late_spans(in));
  const auto k = static_cast<Eigen::Index>(out.windows.size());
  if (k == 0) {
    out.evidence = "no standstill of 0.3 s or more after the motion began to compare the bias with";
    return out;
  }
  const AxisSeries as = compare_with_rest(in, out);
  find_largest_change(out);
  const double ln_n = std::log(static_cast<double>(std::max<Eigen::Index>(k, 2)));
  choose_pattern(fit_patterns(as, ln_n, out), ln_n, out);
  out.evidence = describe_standstills(out);
  return out;
}

}  // namespace eical::dsp::model
