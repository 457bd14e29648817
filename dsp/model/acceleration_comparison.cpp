#include "dsp/model/acceleration_comparison.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace eical::dsp::model {
namespace {

constexpr const char* kAxis = "xyz";

// Two passes of a centred moving average of `len` samples (a triangle, first null at
// fs/len): the same linear filter on both signals leaves their gain untouched and takes the
// modes above the band out.
Eigen::MatrixXd smooth(const Eigen::MatrixXd& x, int len) {
  Eigen::MatrixXd out = x;
  if (len <= 1) return out;
  const Eigen::Index n = x.rows();
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::MatrixXd in = out;
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      std::vector<double> cum(static_cast<std::size_t>(n) + 1, 0.0);
      for (Eigen::Index i = 0; i < n; ++i)
        cum[static_cast<std::size_t>(i) + 1] = cum[static_cast<std::size_t>(i)] + in(i, c);
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Index lo = std::max<Eigen::Index>(0, i - len / 2), hi = std::min<Eigen::Index>(n, lo + len);
        out(i, c) =
            (cum[static_cast<std::size_t>(hi)] - cum[static_cast<std::size_t>(lo)]) / static_cast<double>(hi - lo);
      }
    }
  }
  return out;
}

// x(t − lag) by linear interpolation (lag in samples, either sign).
Eigen::MatrixXd shifted(const Eigen::MatrixXd& x, double lag) {
  Eigen::MatrixXd out(x.rows(), x.cols());
  const Eigen::Index n = x.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = std::clamp(static_cast<double>(i) - lag, 0.0, static_cast<double>(n - 1));
    const auto k = static_cast<Eigen::Index>(std::floor(t));
    const Eigen::Index k1 = std::min(k + 1, n - 1);
    const double f = t - static_cast<double>(k);
    out.row(i) = (1.0 - f) * x.row(k) + f * x.row(k1);
  }
  return out;
}

// The lag (samples) that maximises |Σ y_j(t) x_d(t − k)| over the measured axes j, with the
// parabola through the peak; per jackknife block as well (delete-one sums).
struct LagFit {
  double lag = 0.0, sigma = 0.0;
};
LagFit fit_lag(const Eigen::MatrixXd& y, const Eigen::VectorXd& x, int max_k, Eigen::Index from, Eigen::Index to,
               const std::vector<Eigen::Index>& block_of, int blocks) {
  const int nk = 2 * max_k + 1;
  // sums[b][j][k]
  std::vector<double> sums(static_cast<std::size_t>(blocks) * 3 * static_cast<std::size_t>(nk), 0.0);
  auto at = [&](int b, int j, int k) -> double& {
    return sums[(static_cast<std::size_t>(b) * 3 + static_cast<std::size_t>(j)) * static_cast<std::size_t>(nk) +
                static_cast<std::size_t>(k)];
  };
  for (Eigen::Index i = from; i < to; ++i) {
    const int b = static_cast<int>(block_of[static_cast<std::size_t>(i - from)]);
    for (int k = -max_k; k <= max_k; ++k) {
      const Eigen::Index s = i - k;
      if (s < 0 || s >= x.size()) continue;
      for (int j = 0; j < 3; ++j) at(b, j, k + max_k) += y(i, j) * x[s];
    }
  }
  auto peak = [&](int skip) {
    double best = -1.0, bestv[3] = {0, 0, 0};
    int bk = 0, bj = 0;
    std::vector<double> tot(3 * static_cast<std::size_t>(nk), 0.0);
    for (int b = 0; b < blocks; ++b)
      if (b != skip)
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < nk; ++k) tot[static_cast<std::size_t>(j * nk + k)] += at(b, j, k);
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < nk; ++k)
        if (std::abs(tot[static_cast<std::size_t>(j * nk + k)]) > best)
          best = std::abs(tot[static_cast<std::size_t>(j * nk + k)]), bk = k, bj = j;
    double lag = bk - max_k;
    if (bk > 0 && bk < nk - 1) {
      bestv[0] = std::abs(tot[static_cast<std::size_t>(bj * nk + bk - 1)]), bestv[1] = best,
      bestv[2] = std::abs(tot[static_cast<std::size_t>(bj * nk + bk + 1)]);
      const double den = bestv[0] - 2.0 * bestv[1] + bestv[2];
      if (den < 0.0) lag += 0.5 * (bestv[0] - bestv[2]) / den;
    }
    return lag;
  };
  LagFit f;
  f.lag = peak(-1);
  if (blocks >= 4) {
    std::vector<double> l;
    for (int b = 0; b < blocks; ++b) l.push_back(peak(b));
    double m = 0.0, v = 0.0;
    for (double q : l) m += q;
    m /= static_cast<double>(blocks);
    for (double q : l) v += (q - m) * (q - m);
    f.sigma = std::sqrt(v * static_cast<double>(blocks - 1) / static_cast<double>(blocks));
  }
  return f;
}

// The band-limited signals compared (smoothed: measured y, commanded x) and the rows
// [from, to) clear of the filter's edges and the lag search.
struct BandSignals {
  Eigen::MatrixXd y, x;
  int len = 1, max_k = 1;  // the filter's length, the largest lag searched (samples)
  Eigen::Index from = 0, to = 0;
};

BandSignals band_signals(const RunResiduals& rr, double fs, double cutoff_hz, double max_lag_s) {
  BandSignals b;
  b.len = std::max(1, static_cast<int>(std::lround(fs / cutoff_hz)));
  b.y = smooth(rr.a_meas, b.len), b.x = smooth(rr.a_cmd, b.len);
  b.max_k = std::max(1, static_cast<int>(std::lround(max_lag_s * fs)));
  b.from = 2 * b.len + b.max_k, b.to = rr.n - 2 * b.len - b.max_k;
  return b;
}

// Inputs: commanded axes with acceleration in the band (into c.input). Returns the
// dominant one (-1: not even that one is an input).
int band_inputs(const BandSignals& b, AccelerationComparison& c) {
  Eigen::Vector3d rms = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    rms[i] = std::sqrt(b.x.col(i).segment(b.from, b.to - b.from).squaredNorm() / static_cast<double>(b.to - b.from));
  const double top = rms.maxCoeff();
  int dominant = 0;
  for (int i = 0; i < 3; ++i) {
    c.input[static_cast<std::size_t>(i)] = rms[i] > 0.05 * top && rms[i] > 1.0;  // 1 mm/s² ≈ 0.1 mg
    if (rms[i] > rms[dominant]) dominant = i;
  }
  return c.input[static_cast<std::size_t>(dominant)] ? dominant : -1;
}

// Jackknife blocks: a second or four filter lengths, at most 40 (their count into
// c.blocks). Each row's block.
std::vector<Eigen::Index> jackknife_blocks(const BandSignals& b, double fs, AccelerationComparison& c) {
  const Eigen::Index rows = b.to - b.from;
  const Eigen::Index block_len = std::max<Eigen::Index>({static_cast<Eigen::Index>(fs), 4 * b.len, rows / 40});
  c.blocks = static_cast<int>(rows / block_len);
  std::vector<Eigen::Index> block_of(static_cast<std::size_t>(rows));
  for (Eigen::Index i = 0; i < rows; ++i)
    block_of[static_cast<std::size_t>(i)] = std::min<Eigen::Index>(i / block_len, std::max(0, c.blocks - 1));
  return block_of;
}

// a_meas,j = Σ_i G_ji a_cmd,i(t − τ) + b_j: the normal equations per block, the regressors
// the input columns of xs (the shifted commanded acceleration) and one.
struct BlockNormals {
  int p = 0;  // regressors
  std::vector<Eigen::MatrixXd> xtx, xty;
};

BlockNormals block_normals(const BandSignals& b, const Eigen::MatrixXd& xs, const std::vector<int>& cols,
                           const std::vector<Eigen::Index>& block_of, int blocks) {
  const int p = static_cast<int>(cols.size()) + 1;
  BlockNormals bn{p, std::vector<Eigen::MatrixXd>(static_cast<std::size_t>(blocks), Eigen::MatrixXd::Zero(p, p)),
                  std::vector<Eigen::MatrixXd>(static_cast<std::size_t>(blocks), Eigen::MatrixXd::Zero(p, 3))};
  Eigen::VectorXd r(p);
  for (Eigen::Index i = b.from; i < b.to; ++i) {
    for (int k = 0; k + 1 < p; ++k) r[k] = xs(i, cols[static_cast<std::size_t>(k)]);
    r[p - 1] = 1.0;
    const auto blk = static_cast<std::size_t>(block_of[static_cast<std::size_t>(i - b.from)]);
    bn.xtx[blk].noalias() += r * r.transpose();
    bn.xty[blk].noalias() += r * b.y.row(i);
  }
  return bn;
}

// p × 3: coefficient per regressor, per measured axis, from every block but `skip`.
Eigen::MatrixXd solve_without(const BlockNormals& bn, int skip) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(bn.p, bn.p), bm = Eigen::MatrixXd::Zero(bn.p, 3);
  for (std::size_t blk = 0; blk < bn.xtx.size(); ++blk)
    if (static_cast<int>(blk) != skip) a += bn.xtx[blk], bm += bn.xty[blk];
  return Eigen::MatrixXd(a.ldlt().solve(bm));
}

// The gains' and the bias' block-jackknife standard errors.
void gain_jackknife_sigma(const BlockNormals& bn, const std::vector<int>& cols, AccelerationComparison& c) {
  const int blocks = static_cast<int>(bn.xtx.size()), p = bn.p;
  Eigen::MatrixXd mean = Eigen::MatrixXd::Zero(p, 3), sq = Eigen::MatrixXd::Zero(p, 3);
  for (int b = 0; b < blocks; ++b) {
    const Eigen::MatrixXd bj = solve_without(bn, b);
    mean += bj, sq += bj.cwiseProduct(bj);
  }
  mean /= blocks, sq /= blocks;
  const Eigen::MatrixXd var = ((sq - mean.cwiseProduct(mean)) * static_cast<double>(blocks - 1)).cwiseMax(0.0);
  for (std::size_t k = 0; k < cols.size(); ++k)
    c.gain_sigma.col(cols[k]) = var.row(static_cast<Eigen::Index>(k)).transpose().cwiseSqrt();
  c.bias_sigma_mm_s2 = var.row(p - 1).transpose().cwiseSqrt();
}

// How much of the measured band-limited acceleration the comparison accounts for.
double explained_fraction(const BandSignals& b, const Eigen::MatrixXd& xs, const std::vector<int>& cols,
                          const AccelerationComparison& c) {
  double rss = 0.0, tss = 0.0;
  for (int j = 0; j < 3; ++j) {
    const double mean = b.y.col(j).segment(b.from, b.to - b.from).mean();
    for (Eigen::Index i = b.from; i < b.to; ++i) {
      double pred = c.bias_mm_s2[j];
      for (int col : cols) pred += c.gain(j, col) * xs(i, col);
      rss += (b.y(i, j) - pred) * (b.y(i, j) - pred), tss += (b.y(i, j) - mean) * (b.y(i, j) - mean);
    }
  }
  return tss > 0.0 ? 1.0 - rss / tss : 0.0;
}

}  // namespace

AccelerationComparison compare_accelerations(const RunResiduals& rr, double cutoff_hz, double max_lag_s) {
  AccelerationComparison c;
  if (rr.n < 200 || !(rr.dt_s > 0.0)) {
    c.why = "too few samples to compare accelerations";
    return c;
  }
  const double fs = 1.0 / rr.dt_s;
  c.cutoff_hz = std::min(cutoff_hz, 0.1 * fs);
  const BandSignals b = band_signals(rr, fs, c.cutoff_hz, max_lag_s);
  if (b.to - b.from < 100) {
    c.why = "the run is too short for the band below " + std::to_string(c.cutoff_hz) + " Hz";
    return c;
  }
  const int dominant = band_inputs(b, c);
  if (dominant < 0) {
    c.why = "no commanded acceleration below " + std::to_string(c.cutoff_hz) + " Hz";
    return c;
  }
  const std::vector<Eigen::Index> block_of = jackknife_blocks(b, fs, c);
  const int blocks = std::max(1, c.blocks);
  const LagFit lf = fit_lag(b.y, b.x.col(dominant), b.max_k, b.from, b.to, block_of, blocks);
  c.lag_s = lf.lag * rr.dt_s, c.lag_sigma_s = lf.sigma * rr.dt_s;
  const Eigen::MatrixXd xs = shifted(b.x, lf.lag);
  std::vector<int> cols;
  for (int i = 0; i < 3; ++i)
    if (c.input[static_cast<std::size_t>(i)]) cols.push_back(i);
  const BlockNormals bn = block_normals(b, xs, cols, block_of, blocks);
  const Eigen::MatrixXd beta = solve_without(bn, -1);
  if (!beta.allFinite()) {
    c.why = "the commanded axes' accelerations are not independent in the band";
    return c;
  }
  for (std::size_t k = 0; k < cols.size(); ++k)
    c.gain.col(cols[k]) = beta.row(static_cast<Eigen::Index>(k)).transpose();
  c.bias_mm_s2 = beta.row(bn.p - 1).transpose();
  if (blocks >= 4) gain_jackknife_sigma(bn, cols, c);
  c.explained_fraction = explained_fraction(b, xs, cols, c);
  c.valid = true;
  return c;
}

std::optional<MountingFit> gross_mounting(const RunResiduals& rr, const AccelerationComparison& c) {
  if (!c.valid || c.explained_fraction < 0.2)
    return std::nullopt;  // MEMS noise and a sweep leave little below the modes; the columns decide
  Eigen::Matrix3d p = Eigen::Matrix3d::Zero();
  std::array<bool, 3> row_used{}, decided{};
  bool wrong = false;
  int sensor = -1;
  std::string detail;
  for (int i = 0; i < 3; ++i) {
    if (!c.input[static_cast<std::size_t>(i)]) continue;
    const Eigen::Vector3d col = c.gain.col(i);
    const double norm = col.norm();
    if (norm < 0.3) continue;  // too little of the input arrives to say where
    Eigen::Index j = 0;
    col.cwiseAbs().maxCoeff(&j);
    // A clear image: one measured axis carries it, far outside its uncertainty.
    if (std::abs(col[j]) < 0.9 * norm || std::abs(col[j]) < 5.0 * c.gain_sigma(j, i)) continue;
    const double sign = col[j] > 0.0 ? 1.0 : -1.0;
    if (row_used[static_cast<std::size_t>(j)]) return std::nullopt;  // two inputs onto one axis: no mounting does that
    p(j, i) = sign, row_used[static_cast<std::size_t>(j)] = true, decided[static_cast<std::size_t>(i)] = true;
    char b[160];
    std::snprintf(b, sizeof b, "%scommanded %c is measured as %s%c (gain %.3f +- %.3f)", detail.empty() ? "" : "; ",
                  kAxis[i], sign < 0 ? "-" : "", kAxis[j], col[j], c.gain_sigma(j, i));
    detail += b;
    if (j != i || sign < 0.0) {
      wrong = true;
      const int owner = rr.owner[static_cast<std::size_t>(i)];
      if (sensor < 0) sensor = owner;
    }
  }
  if (!wrong) return std::nullopt;
  if (sensor < 0) sensor = rr.meta.sensor_present[1] ? 1 : 0;
  // Axes not moved: as configured where that machine axis is free, else the one left over.
  for (int i = 0; i < 3; ++i) {
    if (decided[static_cast<std::size_t>(i)]) continue;
    int j = i;
    if (row_used[static_cast<std::size_t>(j)])
      for (j = 0; j < 3 && row_used[static_cast<std::size_t>(j)]; ++j) {
      }
    p(j, i) = 1.0, row_used[static_cast<std::size_t>(j)] = true;
  }
  MountingFit m;
  m.sensor = sensor;
  const Eigen::Matrix3d nominal = rr.meta.sensors[static_cast<std::size_t>(sensor)].to_machine;
  // a_meas = M_nom M_trueᵀ a_cmd = P a_cmd  →  M_true = Pᵀ M_nom = A M_nom: the map A = Pᵀ
  // applied to run.toml's to_machine, in Klipper's axes_map notation (per machine axis, the
  // stated axis with its sign that truly lies along it).
  m.to_machine = p.transpose() * nominal;
  const Eigen::Matrix3d a = p.transpose();
  for (int row = 0; row < 3; ++row) {
    Eigen::Index col = 0;
    a.row(row).cwiseAbs().maxCoeff(&col);
    m.axes_map += std::string(row ? "," : "") + (a(row, col) < 0.0 ? "-" : "") + std::string(1, kAxis[col]);
  }
  std::string unmoved;
  for (int i = 0; i < 3; ++i)
    if (!decided[static_cast<std::size_t>(i)])
      unmoved += std::string(unmoved.empty() ? "" : ", ") + std::string(1, kAxis[i]);
  m.evidence = detail + " (band below " + std::to_string(static_cast<int>(std::lround(c.cutoff_hz))) + " Hz)" +
               (unmoved.empty() ? std::string() : "; " + unmoved + " not moved: taken as configured where free");
  return m;
}

}  // namespace eical::dsp::model
