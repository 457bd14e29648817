#include "dsp/comp/fourier.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

namespace eical::dsp::comp {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Fit {
  Eigen::VectorXd coef;  // [c, a_1, b_1, a_2, b_2, ...]
  Eigen::MatrixXd cov;
  double sigma2 = 0.0;
  int dof = 0;
  Eigen::VectorXd residual;
};

Fit lsq(const std::vector<double>& x_deg, const std::vector<double>& y, const std::vector<int>& freqs, bool constant) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const Eigen::Index k = (constant ? 1 : 0) + 2 * static_cast<Eigen::Index>(freqs.size());
  Eigen::MatrixXd A(n, k);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Index c = 0;
    if (constant) A(i, c++) = 1.0;
    for (int f : freqs) {
      A(i, c++) = std::sin(f * x_deg[static_cast<std::size_t>(i)] * kDeg);
      A(i, c++) = std::cos(f * x_deg[static_cast<std::size_t>(i)] * kDeg);
    }
    b(i) = y[static_cast<std::size_t>(i)];
  }
  Fit fit;
  const Eigen::MatrixXd AtA = A.transpose() * A;
  fit.coef = AtA.ldlt().solve(A.transpose() * b);
  fit.residual = b - A * fit.coef;
  fit.dof = static_cast<int>(n - k);
  fit.sigma2 = fit.dof > 0 ? fit.residual.squaredNorm() / fit.dof : 0.0;
  fit.cov = fit.sigma2 * AtA.inverse();
  return fit;
}

FourierTerm term_of(const Fit& fit, int f, Eigen::Index at, double alpha) {
  FourierTerm t;
  t.frequency = f;
  const double a = fit.coef(at), b = fit.coef(at + 1);
  // A sin(fx + φ) = A cos φ · sin fx + A sin φ · cos fx.
  t.amplitude_arcsec = std::hypot(a, b);
  t.phase_deg = std::atan2(b, a) / kDeg;
  const Eigen::Matrix2d C = fit.cov.block(at, at, 2, 2);
  const Eigen::Vector2d v(a, b);
  t.test_statistic = fit.dof > 0 && C.determinant() > 0 ? v.dot(C.ldlt().solve(v)) / 2.0 : 0.0;
  t.significant = fit.dof > 0 && t.test_statistic > f2_quantile(alpha, fit.dof);
  if (t.amplitude_arcsec > 0) {
    const Eigen::Vector2d g = v / t.amplitude_arcsec;  // ∂A/∂(a, b)
    t.u_amplitude_arcsec = std::sqrt(std::max(0.0, g.dot(C * g)));
  }
  return t;
}

// The interleaved series and the sweep (if one is named), checked.
struct Inputs {
  std::vector<const AngleSeries*> series;
  const AngleSeries* sweep = nullptr;
};

Inputs split_series(const std::vector<AngleSeries>& all, const FourierOptions& opt) {
  Inputs in;
  for (const auto& s : all) {
    if (s.angle_deg.size() != s.deviation_arcsec.size())
      throw InputError("fourier: series '" + s.name + "': angles and deviations differ in count");
    for (std::size_t i = 0; i < s.angle_deg.size(); ++i)
      if (!std::isfinite(s.angle_deg[i]) || !std::isfinite(s.deviation_arcsec[i]))
        throw InputError("fourier: series '" + s.name + "': point " + std::to_string(i + 1) +
                         " is not a finite number");
    if (!opt.sweep_series.empty() && s.name == opt.sweep_series)
      in.sweep = &s;
    else
      in.series.push_back(&s);
  }
  if (!opt.sweep_series.empty() && !in.sweep)
    throw InputError("fourier: no series named '" + opt.sweep_series + "' for the sweep");
  if (in.series.size() < 2) throw InputError("fourier: need at least 2 interleaved series");
  return in;
}

// n: points per revolution of a series (a closing point at +360° is not counted).
int points_per_revolution(const AngleSeries& s) {
  std::set<long long> distinct;
  for (double a : s.angle_deg) distinct.insert(std::llround(std::fmod(std::fmod(a, 360.0) + 360.0, 360.0) * 1e6));
  return static_cast<int>(distinct.size());
}

// The n every series shares; throws when they differ or n < 3.
int common_grid(const std::vector<const AngleSeries*>& series) {
  const int n = points_per_revolution(*series.front());
  for (const auto* s : series)
    if (points_per_revolution(*s) != n)
      throw InputError("fourier: series '" + s->name + "' has " + std::to_string(points_per_revolution(*s)) +
                       " positions, the first has " + std::to_string(n));
  if (n < 3) throw InputError("fourier: a series needs at least 3 positions per revolution");
  return n;
}

// Every series' points, centred onto the first series.
struct Centred {
  std::vector<double> x, y;  // angle (deg), deviation (arcsec)
};

double mean_deviation(const AngleSeries& s) {
  double m = 0.0;
  for (double v : s.deviation_arcsec) m += v;
  return m / static_cast<double>(s.deviation_arcsec.size());
}

// Centring (5, 6) onto the first series; each series' offset into `offsets`.
Centred centre(const std::vector<const AngleSeries*>& series, std::vector<double>& offsets) {
  Centred c;
  const double m1 = mean_deviation(*series.front());
  for (const auto* s : series) {
    const double off = mean_deviation(*s) - m1;
    offsets.push_back(off);
    for (std::size_t i = 0; i < s->angle_deg.size(); ++i) {
      c.x.push_back(s->angle_deg[i]);
      c.y.push_back(s->deviation_arcsec[i] - off);
    }
  }
  return c;
}

// Amplitude spectrum of the centred data, 0..f_max (direct DFT on the possibly irregular grid).
std::vector<double> amplitude_spectrum(const Centred& c, int f_max) {
  const int n_total = static_cast<int>(c.x.size());
  std::vector<double> power(static_cast<std::size_t>(f_max + 1), 0.0);
  double ymean = 0.0;
  for (double v : c.y) ymean += v;
  ymean /= n_total;
  for (int f = 1; f <= f_max; ++f) {
    double s = 0.0, co = 0.0;
    for (int i = 0; i < n_total; ++i) {
      s += (c.y[static_cast<std::size_t>(i)] - ymean) * std::sin(f * c.x[static_cast<std::size_t>(i)] * kDeg);
      co += (c.y[static_cast<std::size_t>(i)] - ymean) * std::cos(f * c.x[static_cast<std::size_t>(i)] * kDeg);
    }
    power[static_cast<std::size_t>(f)] = 2.0 * std::hypot(s, co) / n_total;  // amplitude estimate
  }
  return power;
}

// The lines above candidate_sigma times the spectrum's noise level (its median amplitude,
// robust to the few real lines), f = k·n left out (centring removed them).
std::vector<int> candidate_frequencies(const std::vector<double>& power, int n, double candidate_sigma) {
  const int f_max = static_cast<int>(power.size()) - 1;
  std::vector<double> sorted;
  for (int f = 1; f <= f_max; ++f)
    if (f % n != 0) sorted.push_back(power[static_cast<std::size_t>(f)]);
  std::sort(sorted.begin(), sorted.end());
  const double noise = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  std::vector<int> cand;
  for (int f = 1; f <= f_max; ++f)
    if (f % n != 0 && power[static_cast<std::size_t>(f)] > candidate_sigma * noise * 1.4826) cand.push_back(f);
  return cand;
}

// Least squares, dropping the least significant term until all are significant: `cand`
// keeps the significant frequencies, `rejected` receives the dropped terms.
Fit fit_significant(const Centred& c, std::vector<int>& cand, double alpha, std::vector<FourierTerm>& rejected) {
  Fit fit;
  for (;;) {
    fit = lsq(c.x, c.y, cand, true);
    if (cand.empty()) break;
    int worst = -1;
    double worst_stat = kInf;
    for (std::size_t l = 0; l < cand.size(); ++l) {
      const FourierTerm t = term_of(fit, cand[l], 1 + 2 * static_cast<Eigen::Index>(l), alpha);
      if (!t.significant && t.test_statistic < worst_stat) worst_stat = t.test_statistic, worst = static_cast<int>(l);
    }
    if (worst < 0) break;
    rejected.push_back(term_of(fit, cand[static_cast<std::size_t>(worst)], 1 + 2 * worst, alpha));
    cand.erase(cand.begin() + worst);
  }
  return fit;
}

// u_x: the fitted function's standard uncertainty, RMS over the measured positions.
double function_uncertainty(const Centred& c, const std::vector<int>& cand, const Fit& fit) {
  const int n_total = static_cast<int>(c.x.size());
  double ux2 = 0.0;
  for (int i = 0; i < n_total; ++i) {
    Eigen::VectorXd g(1 + 2 * static_cast<Eigen::Index>(cand.size()));
    g(0) = 0.0;  // the constant is a reference offset, not part of F
    for (std::size_t l = 0; l < cand.size(); ++l) {
      g(1 + 2 * static_cast<Eigen::Index>(l)) = std::sin(cand[l] * c.x[static_cast<std::size_t>(i)] * kDeg);
      g(2 + 2 * static_cast<Eigen::Index>(l)) = std::cos(cand[l] * c.x[static_cast<std::size_t>(i)] * kDeg);
    }
    ux2 += g.dot(fit.cov * g);
  }
  return std::sqrt(ux2 / n_total);
}

// Throws unless the sweep covers one interval and falls on enough of its phases. A sweep
// moves continuously over the interval: its positions fall on many phases of it. Positions
// on the interleaved grid only (e.g. one of the series named as the sweep) see every
// f = k·n as a constant — the fit is singular and would print an amplitude of 1e12.
void check_sweep(const AngleSeries& sweep, int n, std::size_t n_kn) {
  const double span = *std::max_element(sweep.angle_deg.begin(), sweep.angle_deg.end()) -
                      *std::min_element(sweep.angle_deg.begin(), sweep.angle_deg.end());
  if (span < 360.0 / n * 0.95)
    throw InputError("fourier: the sweep covers " + std::to_string(span) + " deg, less than one interval (" +
                     std::to_string(360.0 / n) + " deg)");
  const double interval = 360.0 / n;
  std::set<long long> phases;
  for (double a : sweep.angle_deg) {
    const double ph = std::fmod(std::fmod(a, interval) + interval, interval);
    phases.insert(std::llround(ph * 1e3) % std::llround(interval * 1e3));  // 0.001° resolution
  }
  const std::size_t needed = 2 * n_kn + 2;
  if (phases.size() < needed)
    throw InputError("fourier: series '" + sweep.name + "' is not a sweep: its " +
                     std::to_string(sweep.angle_deg.size()) + " positions fall on " + std::to_string(phases.size()) +
                     " phase(s) of the " + std::to_string(interval) +
                     " deg interval; a sweep moves continuously over one interval (at least " + std::to_string(needed) +
                     " phases for " + std::to_string(n_kn) + " frequencies k*n)");
}

// f = k·n from the continuous sweep over one interval, after removing the other terms:
// the significant ones into r.terms, the others into `rejected`.
void add_sweep_terms(const AngleSeries& sweep, int n, double alpha, FourierResult& r,
                     std::vector<FourierTerm>& rejected) {
  std::vector<double> sy;
  for (std::size_t i = 0; i < sweep.angle_deg.size(); ++i)
    sy.push_back(sweep.deviation_arcsec[i] - r.evaluate(sweep.angle_deg[i]));
  std::vector<int> kn(r.lost_frequencies.begin(), r.lost_frequencies.end());
  if (kn.empty()) kn.push_back(n);
  check_sweep(sweep, n, kn.size());
  const Fit sf = lsq(sweep.angle_deg, sy, kn, true);
  for (Eigen::Index i = 0; i < sf.coef.size(); ++i)
    if (!std::isfinite(sf.coef(i)) || !(sf.cov(i, i) >= 0.0) || !std::isfinite(sf.cov(i, i)))
      throw InputError("fourier: the sweep '" + sweep.name +
                       "' does not determine the f = k*n terms (singular fit): spread it over the interval");
  for (std::size_t l = 0; l < kn.size(); ++l) {
    FourierTerm t = term_of(sf, kn[l], 1 + 2 * static_cast<Eigen::Index>(l), alpha);
    t.from_sweep = true;
    if (t.significant)
      r.terms.push_back(t);
    else
      rejected.push_back(t);
  }
}

}  // namespace

double f2_quantile(double alpha, double nu) { return nu / 2.0 * (std::pow(alpha, -2.0 / nu) - 1.0); }

double FourierResult::evaluate(double angle_deg) const {
  double s = 0.0;
  for (const auto& t : terms)
    if (t.significant) s += t.amplitude_arcsec * std::sin(t.frequency * angle_deg * kDeg + t.phase_deg * kDeg);
  return s;
}

FourierResult fourier_calibration(const std::vector<AngleSeries>& series, const FourierOptions& options) {
  const Inputs in = split_series(series, options);
  FourierResult r;
  r.series = static_cast<int>(in.series.size());
  r.points_per_series = common_grid(in.series);
  const int n = r.points_per_series;
  const Centred c = centre(in.series, r.series_offset_arcsec);
  const int f_max = options.max_frequency > 0 ? options.max_frequency : std::max(1, n * r.series / 2 - 1);
  for (int k = 1; k * n <= f_max; ++k) r.lost_frequencies.push_back(k * n);
  std::vector<int> cand = candidate_frequencies(amplitude_spectrum(c, f_max), n, options.candidate_sigma);
  std::vector<FourierTerm> rejected;
  const Fit fit = fit_significant(c, cand, options.alpha, rejected);
  for (std::size_t l = 0; l < cand.size(); ++l)
    r.terms.push_back(term_of(fit, cand[l], 1 + 2 * static_cast<Eigen::Index>(l), options.alpha));
  r.u_x_arcsec = function_uncertainty(c, cand, fit);
  r.residual_rms_arcsec = std::sqrt(fit.residual.squaredNorm() / static_cast<int>(c.x.size()));
  if (in.sweep) add_sweep_terms(*in.sweep, n, options.alpha, r, rejected);
  std::sort(r.terms.begin(), r.terms.end(), [](const auto& a, const auto& b) { return a.frequency < b.frequency; });
  r.terms.insert(r.terms.end(), rejected.begin(), rejected.end());
  r.u_p_arcsec = options.positioning_bound_arcsec / std::sqrt(3.0);
  r.expanded_U_arcsec = 2.0 * std::hypot(r.u_x_arcsec, r.u_p_arcsec);  // (10), (11), k = 2
  return r;
}

}  // namespace eical::dsp::comp
