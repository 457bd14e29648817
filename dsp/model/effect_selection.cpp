#include "dsp/model/effect_selection.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>

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

SelectionResult select_effects(const Eigen::VectorXd& residual, const std::vector<Candidate>& candidates,
                               const std::vector<bool>& heldout, const SelectionOptions& opt) {
  const Eigen::Index n = residual.size();
  if (static_cast<Eigen::Index>(heldout.size()) != n)
    throw InputError("effect selection: held-out mask size differs from the residual");
  if (!residual.allFinite()) throw InputError("effect selection: residual holds non-finite values");
  Split s;
  for (Eigen::Index i = 0; i < n; ++i) (heldout[static_cast<std::size_t>(i)] ? s.check : s.fit).push_back(i);
  if (s.fit.size() < 10 || s.check.empty()) throw InputError("effect selection: need fitting and held-out samples");
  for (const auto& c : candidates) {
    if (c.regressors.rows() != n)
      throw InputError("effect selection: candidate '" + c.name + "' has the wrong number of rows");
    if (!c.regressors.allFinite())
      throw InputError("effect selection: candidate '" + c.name + "' has non-finite regressors");
  }

  const Eigen::VectorXd y_fit = rows(residual, s.fit), y_chk = rows(residual, s.check);
  SelectionResult out;
  out.rms_nominal = rms(y_fit);
  out.heldout_rms_nominal = rms(y_chk);
  const double nf = static_cast<double>(s.fit.size());
  // The effective count is the noise's: the residual's autocorrelation once every
  // candidate is fitted (a structured residual — the very effects to be found — is smooth
  // and would count as a handful of samples, hiding them).
  {
    Eigen::MatrixXd all(static_cast<Eigen::Index>(s.fit.size()), 0);
    for (const auto& c : candidates) all = hcat(all, rows(c.regressors, s.fit));
    const Eigen::VectorXd noise = all.cols() > 0 && all.cols() < static_cast<Eigen::Index>(s.fit.size()) / 4
                                      ? Eigen::VectorXd(y_fit - all * solve(all, y_fit))
                                      : y_fit;
    out.n_eff = nf / integrated_autocorrelation_time(noise);
  }

  Eigen::MatrixXd accepted_fit(static_cast<Eigen::Index>(s.fit.size()), 0),
      accepted_chk(static_cast<Eigen::Index>(s.check.size()), 0);
  Eigen::MatrixXd accepted_all(n, 0);
  std::vector<bool> done(candidates.size(), false);
  auto bic = [&](double rss, Eigen::Index p) {
    return out.n_eff * std::log(std::max(rss, 1e-300) / nf) + static_cast<double>(p) * std::log(out.n_eff);
  };
  Eigen::VectorXd cur_fit = y_fit, cur_chk = y_chk;
  double cur_bic = bic(y_fit.squaredNorm(), 0);

  for (int round = 0; round < opt.max_effects; ++round) {
    int best = -1;
    double best_drop = -kInf;
    EffectVerdict best_v;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (done[k]) continue;
      const Eigen::MatrixXd Af = hcat(accepted_fit, rows(candidates[k].regressors, s.fit));
      const Eigen::MatrixXd Ac = hcat(accepted_chk, rows(candidates[k].regressors, s.check));
      const Eigen::VectorXd x = solve(Af, y_fit);
      const Eigen::VectorXd rf = y_fit - Af * x, rc = y_chk - Ac * x;
      EffectVerdict v;
      v.name = candidates[k].name;
      v.bic_drop = cur_bic - bic(rf.squaredNorm(), Af.cols());
      v.rms_before = rms(cur_fit), v.rms_after = rms(rf);
      v.heldout_rms_before = rms(cur_chk), v.heldout_rms_after = rms(rc);
      for (Eigen::Index c = 0; c < candidates[k].regressors.cols(); ++c)
        v.correlation =
            std::max(v.correlation, abs_corr(cur_fit, rows(Eigen::VectorXd(candidates[k].regressors.col(c)), s.fit)));
      v.param_names = candidates[k].param_names;
      v.params = x.tail(candidates[k].regressors.cols());
      // Only an extension that also predicts the held-out data better may be taken.
      const bool gain = v.heldout_rms_after < (1.0 - opt.min_heldout_gain) * v.heldout_rms_before;
      if (gain && v.bic_drop > best_drop) best_drop = v.bic_drop, best = static_cast<int>(k), best_v = v;
    }
    if (best < 0 || best_v.bic_drop < opt.min_bic_drop) break;
    best_v.significant = true;
    done[static_cast<std::size_t>(best)] = true;
    const auto& cand = candidates[static_cast<std::size_t>(best)];
    accepted_fit = hcat(accepted_fit, rows(cand.regressors, s.fit));
    accepted_chk = hcat(accepted_chk, rows(cand.regressors, s.check));
    accepted_all = hcat(accepted_all, cand.regressors);
    const Eigen::VectorXd x = solve(accepted_fit, y_fit);
    cur_fit = y_fit - accepted_fit * x;
    cur_chk = y_chk - accepted_chk * x;
    cur_bic = bic(cur_fit.squaredNorm(), accepted_fit.cols());
    out.effects.push_back(best_v);
  }
  // Parameters of the accepted effects from the final joint fit.
  if (accepted_fit.cols() > 0) {
    const Eigen::VectorXd x = solve(accepted_fit, y_fit);
    // cov = (AᵀA)⁻¹ · RSS / n_eff: the residual's variance counted per independent sample.
    const Eigen::MatrixXd ata = accepted_fit.transpose() * accepted_fit;
    const Eigen::VectorXd var =
        ata.completeOrthogonalDecomposition().pseudoInverse().diagonal() *
        ((y_fit - accepted_fit * x).squaredNorm() / std::max(out.n_eff - static_cast<double>(x.size()), 1.0));
    std::vector<int> fit_blocks;
    if (!opt.block.empty())
      for (Eigen::Index i : s.fit) fit_blocks.push_back(opt.block[static_cast<std::size_t>(i)]);
    const Eigen::VectorXd jack = jackknife_sigma(accepted_fit, y_fit, fit_blocks);
    Eigen::Index off = 0;
    for (auto& e : out.effects) {
      e.params = x.segment(off, static_cast<Eigen::Index>(e.param_names.size()));
      e.param_sigma = var.segment(off, static_cast<Eigen::Index>(e.param_names.size()))
                          .cwiseMax(0.0)
                          .cwiseSqrt()
                          .cwiseMax(jack.segment(off, static_cast<Eigen::Index>(e.param_names.size())));
      off += static_cast<Eigen::Index>(e.param_names.size());
    }
    out.final_residual = residual - accepted_all * x;
  } else {
    out.final_residual = residual;
  }
  out.rms_final = rms(cur_fit);
  out.heldout_rms_final = rms(cur_chk);
  // The rejected candidates, tested once more against the final model, most telling first.
  std::vector<EffectVerdict> rejected;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (done[k]) continue;
    const Eigen::MatrixXd Af = hcat(accepted_fit, rows(candidates[k].regressors, s.fit));
    const Eigen::MatrixXd Ac = hcat(accepted_chk, rows(candidates[k].regressors, s.check));
    const Eigen::VectorXd x = solve(Af, y_fit);
    EffectVerdict v;
    v.name = candidates[k].name;
    v.bic_drop = cur_bic - bic((y_fit - Af * x).squaredNorm(), Af.cols());
    v.rms_before = rms(cur_fit), v.rms_after = rms(y_fit - Af * x);
    v.heldout_rms_before = rms(cur_chk), v.heldout_rms_after = rms(y_chk - Ac * x);
    v.param_names = candidates[k].param_names;
    v.params = x.tail(candidates[k].regressors.cols());
    for (Eigen::Index c = 0; c < candidates[k].regressors.cols(); ++c)
      v.correlation =
          std::max(v.correlation, abs_corr(cur_fit, rows(Eigen::VectorXd(candidates[k].regressors.col(c)), s.fit)));
    rejected.push_back(v);
  }
  std::sort(rejected.begin(), rejected.end(), [](const auto& a, const auto& b) { return a.bic_drop > b.bic_drop; });
  out.effects.insert(out.effects.end(), rejected.begin(), rejected.end());
  return out;
}

}  // namespace eical::dsp::model
