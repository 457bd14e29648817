#include "dsp/model/effect_selection.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <utility>

namespace eical::dsp::model {
namespace {

struct Split {
  std::vector<Eigen::Index> fit, check;
};

Eigen::MatrixXd rows(const Eigen::MatrixXd& m, const std::vector<Eigen::Index>& idx) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(idx.size()), m.cols());
  for (std::size_t i = 0; i < idx.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = m.row(idx[i]);
  return out;
}

Eigen::VectorXd rows(const Eigen::VectorXd& v, const std::vector<Eigen::Index>& idx) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(idx.size()));
  for (std::size_t i = 0; i < idx.size(); ++i) out(static_cast<Eigen::Index>(i)) = v(idx[i]);
  return out;
}

double rms(const Eigen::VectorXd& v) {
  return v.size() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.size())) : 0.0;
}

// Least squares with column scaling (regressors differ by orders of magnitude).
Eigen::VectorXd solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
  if (A.cols() == 0) return {};
  Eigen::VectorXd norm = A.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < norm.size(); ++c)
    if (norm(c) <= 0.0) norm(c) = 1.0;
  return (A * norm.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(y).cwiseQuotient(norm);
}

Eigen::MatrixXd hcat(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.cols() == 0) return b;
  Eigen::MatrixXd m(a.rows(), a.cols() + b.cols());
  m << a, b;
  return m;
}

double abs_corr(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd x = a.array() - a.mean(), y = b.array() - b.mean();
  const double d = x.norm() * y.norm();
  return d > 0.0 ? std::abs(x.dot(y)) / d : 0.0;
}

// Block-jackknife standard errors of the least-squares parameters of A·x ≈ y: each block
// left out in turn (the normal equations less its share), the spread of the refits.
Eigen::VectorXd jackknife_sigma(const Eigen::MatrixXd& A, const Eigen::VectorXd& y, const std::vector<int>& block) {
  const Eigen::Index p = A.cols();
  if (block.size() != static_cast<std::size_t>(A.rows()) || p == 0) return Eigen::VectorXd::Zero(p);
  Eigen::VectorXd norm = A.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < p; ++c)
    if (norm(c) <= 0.0) norm(c) = 1.0;
  const Eigen::MatrixXd As = A * norm.cwiseInverse().asDiagonal();
  std::vector<int> ids(block);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  if (ids.size() < 4) return Eigen::VectorXd::Zero(p);
  const Eigen::MatrixXd ata = As.transpose() * As;
  const Eigen::VectorXd aty = As.transpose() * y;
  std::vector<Eigen::VectorXd> est;
  for (int b : ids) {
    Eigen::MatrixXd m = ata;
    Eigen::VectorXd v = aty;
    for (Eigen::Index i = 0; i < As.rows(); ++i)
      if (block[static_cast<std::size_t>(i)] == b)
        m -= As.row(i).transpose() * As.row(i), v -= As.row(i).transpose() * y[i];
    est.push_back(m.completeOrthogonalDecomposition().solve(v).cwiseQuotient(norm));
  }
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(p), var = Eigen::VectorXd::Zero(p);
  for (const auto& e : est) mean += e;
  mean /= static_cast<double>(est.size());
  for (const auto& e : est) var += (e - mean).cwiseAbs2();
  const double nb = static_cast<double>(est.size());
  return (var * (nb - 1.0) / nb).cwiseSqrt();
}

}  // namespace

double integrated_autocorrelation_time(const Eigen::VectorXd& x, int max_lag) {
  const Eigen::Index n = x.size();
  if (n < 3) return 1.0;
  const Eigen::VectorXd d = x.array() - x.mean();
  const double c0 = d.squaredNorm();
  if (c0 <= 0.0) return 1.0;
  double tau = 1.0;
  // Every lag while lags are short, then a step growing with the lag (2 % of it): the
  // sum stays a fair Riemann sum of a smooth autocorrelation at O(n·log L) cost.
  const Eigen::Index lag_max = std::min<Eigen::Index>(max_lag, n / 2);
  for (Eigen::Index lag = 1; lag < lag_max;) {
    const Eigen::Index step = std::max<Eigen::Index>(1, lag / 50);
    const double c = d.head(n - lag).dot(d.tail(n - lag)) / c0;
    if (c <= 0.0) break;
    tau += 2.0 * c * static_cast<double>(step);
    lag += step;
  }
  return tau;
}

namespace {

// What the forward selection fits: the candidates, the split of the samples, the residual
// on each set, and the effective count of the fitting set.
struct SelectionData {
  const std::vector<Candidate>& candidates;
  Split s;
  Eigen::VectorXd y_fit, y_chk;
  double nf = 0.0, n_eff = 0.0;

  // BIC = n_eff · ln(RSS/n) + p · ln(n_eff).
  [[nodiscard]] double bic(double rss, Eigen::Index p) const {
    return n_eff * std::log(std::max(rss, 1e-300) / nf) + static_cast<double>(p) * std::log(n_eff);
  }
};

// The model accepted so far: its regressors (fitting rows, held-out rows, all rows), the
// residuals it leaves on either set and its BIC.
struct AcceptedModel {
  Eigen::MatrixXd fit, chk, all;
  Eigen::VectorXd cur_fit, cur_chk;
  double cur_bic = 0.0;
};

void check_residual(const Eigen::VectorXd& residual, const std::vector<bool>& heldout) {
  if (static_cast<Eigen::Index>(heldout.size()) != residual.size())
    throw InputError("effect selection: held-out mask size differs from the residual");
  if (!residual.allFinite()) throw InputError("effect selection: residual holds non-finite values");
}

Split split_samples(const std::vector<bool>& heldout) {
  Split s;
  for (std::size_t i = 0; i < heldout.size(); ++i)
    (heldout[i] ? s.check : s.fit).push_back(static_cast<Eigen::Index>(i));
  if (s.fit.size() < 10 || s.check.empty()) throw InputError("effect selection: need fitting and held-out samples");
  return s;
}

void check_candidates(const std::vector<Candidate>& candidates, Eigen::Index n) {
  for (const auto& c : candidates) {
    if (c.regressors.rows() != n)
      throw InputError("effect selection: candidate '" + c.name + "' has the wrong number of rows");
    if (!c.regressors.allFinite())
      throw InputError("effect selection: candidate '" + c.name + "' has non-finite regressors");
  }
}

// The effective count is the noise's: the residual's autocorrelation once every
// candidate is fitted (a structured residual — the very effects to be found — is smooth
// and would count as a handful of samples, hiding them).
double effective_count(const std::vector<Candidate>& candidates, const Split& s, const Eigen::VectorXd& y_fit) {
  Eigen::MatrixXd all(static_cast<Eigen::Index>(s.fit.size()), 0);
  for (const auto& c : candidates) all = hcat(all, rows(c.regressors, s.fit));
  const Eigen::VectorXd noise = all.cols() > 0 && all.cols() < static_cast<Eigen::Index>(s.fit.size()) / 4
                                    ? Eigen::VectorXd(y_fit - all * solve(all, y_fit))
                                    : y_fit;
  return static_cast<double>(s.fit.size()) / integrated_autocorrelation_time(noise);
}

// |corr| of the residual with the candidate's best single regressor (fitting rows).
double best_correlation(const Eigen::VectorXd& cur_fit, const Candidate& c, const Split& s) {
  double r = 0.0;
  for (Eigen::Index col = 0; col < c.regressors.cols(); ++col)
    r = std::max(r, abs_corr(cur_fit, rows(Eigen::VectorXd(c.regressors.col(col)), s.fit)));
  return r;
}

// A candidate added to the accepted model: what it gains on either set.
EffectVerdict trial(const SelectionData& d, const AcceptedModel& m, const Candidate& c) {
  const Eigen::MatrixXd Af = hcat(m.fit, rows(c.regressors, d.s.fit));
  const Eigen::MatrixXd Ac = hcat(m.chk, rows(c.regressors, d.s.check));
  const Eigen::VectorXd x = solve(Af, d.y_fit);
  const Eigen::VectorXd rf = d.y_fit - Af * x, rc = d.y_chk - Ac * x;
  EffectVerdict v;
  v.name = c.name;
  v.bic_drop = m.cur_bic - d.bic(rf.squaredNorm(), Af.cols());
  v.rms_before = rms(m.cur_fit), v.rms_after = rms(rf);
  v.heldout_rms_before = rms(m.cur_chk), v.heldout_rms_after = rms(rc);
  v.correlation = best_correlation(m.cur_fit, c, d.s);
  v.param_names = c.param_names;
  v.params = x.tail(c.regressors.cols());
  return v;
}

// The candidate with the largest BIC drop among those that also predict the held-out data
// better (-1: none).
int best_candidate(const SelectionData& d, const AcceptedModel& m, const std::vector<bool>& done,
                   const SelectionOptions& opt, EffectVerdict& best_v) {
  int best = -1;
  double best_drop = -kInf;
  for (std::size_t k = 0; k < d.candidates.size(); ++k) {
    if (done[k]) continue;
    EffectVerdict v = trial(d, m, d.candidates[k]);
    // Only an extension that also predicts the held-out data better may be taken.
    const bool gain = v.heldout_rms_after < (1.0 - opt.min_heldout_gain) * v.heldout_rms_before;
    if (gain && v.bic_drop > best_drop) best_drop = v.bic_drop, best = static_cast<int>(k), best_v = v;
  }
  return best;
}

// The candidate into the model, which is refitted.
void accept(const SelectionData& d, const Candidate& cand, AcceptedModel& m) {
  m.fit = hcat(m.fit, rows(cand.regressors, d.s.fit));
  m.chk = hcat(m.chk, rows(cand.regressors, d.s.check));
  m.all = hcat(m.all, cand.regressors);
  const Eigen::VectorXd x = solve(m.fit, d.y_fit);
  m.cur_fit = d.y_fit - m.fit * x;
  m.cur_chk = d.y_chk - m.chk * x;
  m.cur_bic = d.bic(m.cur_fit.squaredNorm(), m.fit.cols());
}

// Parameters of the accepted effects from the final joint fit, with their standard errors;
// the residual of all samples after them.
void joint_parameters(const SelectionData& d, const AcceptedModel& m, const Eigen::VectorXd& residual,
                      const SelectionOptions& opt, SelectionResult& out) {
  if (m.fit.cols() == 0) {
    out.final_residual = residual;
    return;
  }
  const Eigen::VectorXd x = solve(m.fit, d.y_fit);
  // cov = (AᵀA)⁻¹ · RSS / n_eff: the residual's variance counted per independent sample.
  const Eigen::MatrixXd ata = m.fit.transpose() * m.fit;
  const Eigen::VectorXd var =
      ata.completeOrthogonalDecomposition().pseudoInverse().diagonal() *
      ((d.y_fit - m.fit * x).squaredNorm() / std::max(out.n_eff - static_cast<double>(x.size()), 1.0));
  std::vector<int> fit_blocks;
  if (!opt.block.empty())
    for (Eigen::Index i : d.s.fit) fit_blocks.push_back(opt.block[static_cast<std::size_t>(i)]);
  const Eigen::VectorXd jack = jackknife_sigma(m.fit, d.y_fit, fit_blocks);
  Eigen::Index off = 0;
  for (auto& e : out.effects) {
    e.params = x.segment(off, static_cast<Eigen::Index>(e.param_names.size()));
    e.param_sigma = var.segment(off, static_cast<Eigen::Index>(e.param_names.size()))
                        .cwiseMax(0.0)
                        .cwiseSqrt()
                        .cwiseMax(jack.segment(off, static_cast<Eigen::Index>(e.param_names.size())));
    off += static_cast<Eigen::Index>(e.param_names.size());
  }
  out.final_residual = residual - m.all * x;
}

// The rejected candidates, tested once more against the final model, most telling first.
std::vector<EffectVerdict> rejected_verdicts(const SelectionData& d, const AcceptedModel& m,
                                             const std::vector<bool>& done) {
  std::vector<EffectVerdict> rejected;
  for (std::size_t k = 0; k < d.candidates.size(); ++k) {
    if (done[k]) continue;
    const Candidate& c = d.candidates[k];
    const Eigen::MatrixXd Af = hcat(m.fit, rows(c.regressors, d.s.fit));
    const Eigen::MatrixXd Ac = hcat(m.chk, rows(c.regressors, d.s.check));
    const Eigen::VectorXd x = solve(Af, d.y_fit);
    EffectVerdict v;
    v.name = c.name;
    v.bic_drop = m.cur_bic - d.bic((d.y_fit - Af * x).squaredNorm(), Af.cols());
    v.rms_before = rms(m.cur_fit), v.rms_after = rms(d.y_fit - Af * x);
    v.heldout_rms_before = rms(m.cur_chk), v.heldout_rms_after = rms(d.y_chk - Ac * x);
    v.param_names = c.param_names;
    v.params = x.tail(c.regressors.cols());
    v.correlation = best_correlation(m.cur_fit, c, d.s);
    rejected.push_back(v);
  }
  std::sort(rejected.begin(), rejected.end(), [](const auto& a, const auto& b) { return a.bic_drop > b.bic_drop; });
  return rejected;
}

}  // namespace

SelectionResult select_effects(const Eigen::VectorXd& residual, const std::vector<Candidate>& candidates,
                               const std::vector<bool>& heldout, const SelectionOptions& options) {
  const Eigen::Index n = residual.size();
  check_residual(residual, heldout);
  Split s = split_samples(heldout);
  check_candidates(candidates, n);
  Eigen::VectorXd y_fit = rows(residual, s.fit), y_chk = rows(residual, s.check);
  const double nf = static_cast<double>(s.fit.size()), n_eff = effective_count(candidates, s, y_fit);
  const SelectionData d{candidates, std::move(s), std::move(y_fit), std::move(y_chk), nf, n_eff};
  SelectionResult out;
  out.rms_nominal = rms(d.y_fit);
  out.heldout_rms_nominal = rms(d.y_chk);
  out.n_eff = d.n_eff;

  AcceptedModel m{.fit = Eigen::MatrixXd(static_cast<Eigen::Index>(d.s.fit.size()), 0),
                  .chk = Eigen::MatrixXd(static_cast<Eigen::Index>(d.s.check.size()), 0),
                  .all = Eigen::MatrixXd(n, 0),
                  .cur_fit = d.y_fit,
                  .cur_chk = d.y_chk,
                  .cur_bic = d.bic(d.y_fit.squaredNorm(), 0)};
  std::vector<bool> done(candidates.size(), false);
  for (int round = 0; round < options.max_effects; ++round) {
    EffectVerdict best_v;
    const int best = best_candidate(d, m, done, options, best_v);
    if (best < 0 || best_v.bic_drop < options.min_bic_drop) break;
    best_v.significant = true;
    done[static_cast<std::size_t>(best)] = true;
    accept(d, candidates[static_cast<std::size_t>(best)], m);
    out.effects.push_back(best_v);
  }
  joint_parameters(d, m, residual, options, out);
  out.rms_final = rms(m.cur_fit);
  out.heldout_rms_final = rms(m.cur_chk);
  const std::vector<EffectVerdict> rejected = rejected_verdicts(d, m, done);
  out.effects.insert(out.effects.end(), rejected.begin(), rejected.end());
  return out;
}

}  // namespace eical::dsp::model
