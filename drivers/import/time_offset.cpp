#include "drivers/import/time_offset.hpp"

#include "dsp/core/error.hpp"
#include "sim/sensor/pt2.hpp"

#include <Eigen/LU>
#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

namespace eical::drivers {
namespace {

constexpr int kBlocks = 16;

// Score Σ_i c_iᵀ G⁻¹ c_i of a 3 × ncols correlation matrix.
double score(const Eigen::MatrixXd& c, const Eigen::MatrixXd& g_inv) { return (c * g_inv * c.transpose()).trace(); }

// Sub-step peak of scores s[0..n): the best interior point and a parabola through it and
// its neighbours (at an edge: the edge itself).
double peak(const std::vector<double>& s) {
  const auto best = static_cast<std::size_t>(std::max_element(s.begin(), s.end()) - s.begin());
  if (best == 0 || best + 1 == s.size()) return static_cast<double>(best);
  const double a = s[best - 1], b = s[best], c = s[best + 1];
  const double den = a - 2.0 * b + c;
  return static_cast<double>(best) + (den < 0.0 ? 0.5 * (a - c) / den : 0.0);
}

}  // namespace

OffsetEstimate estimate_offset(const MeasuredSeries& y_in, const ReferenceSignal& ref, int F) {
  if (!(y_in.fs_hz > 0.0) || y_in.grid_index.size() != y_in.values.size() || y_in.values.size() < 16)
    throw dsp::InputError("time offset: the measurement needs a rate and at least 16 samples");
  if (!(ref.t_end_s > ref.t_begin_s) || !ref.accel)
    throw dsp::InputError("time offset: the reference has no time span");
  if (F < 1) throw dsp::InputError("time offset: oversample must be >= 1");
  std::vector<int> cols;
  for (int j = 0; j < 3; ++j)
    if (ref.moving[j] != 0.0) cols.push_back(j);
  if (cols.empty()) throw dsp::InputError("time offset: the reference moves no axis");
  const auto nc = static_cast<int>(cols.size());
  const double fs = y_in.fs_hz, hf = 1.0 / (fs * F);

  // The reference on the fine grid through the sensor's low-pass, mean removed.
  const auto m_fine = static_cast<std::size_t>(std::floor((ref.t_end_s - ref.t_begin_s) / hf)) + 1;
  std::vector<std::vector<double>> rf(cols.size(), std::vector<double>(m_fine));
  {
    std::vector<sim::Pt2> lp;
    if (ref.sensor_f0_hz > 0.0)
      for (int c = 0; c < nc; ++c) lp.emplace_back(ref.sensor_f0_hz, ref.sensor_zeta, hf);
    std::vector<double> prev(cols.size(), 0.0);
    for (std::size_t m = 0; m < m_fine; ++m) {
      const Eigen::Vector3d a = ref.accel(ref.t_begin_s + static_cast<double>(m) * hf);
      for (std::size_t c = 0; c < cols.size(); ++c) {
        const double x = a[cols[c]];
        rf[c][m] = lp.empty() ? x : lp[c].step(m == 0 ? x : 0.5 * (prev[c] + x));
        prev[c] = x;
      }
    }
    for (auto& r : rf) {
      double mean = 0.0;
      for (double v : r) mean += v;
      mean /= static_cast<double>(r.size());
      for (double& v : r) v -= mean;
    }
  }
  const std::size_t m_coarse = (m_fine - 1) / static_cast<std::size_t>(F) + 1;

  // The measurement on its grid, mean removed, lost frames zero.
  const auto n = static_cast<std::size_t>(y_in.grid_index.back() - y_in.grid_index.front()) + 1;
  std::vector<std::vector<double>> y(3, std::vector<double>(n, 0.0));
  std::vector<bool> valid(n, false);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : y_in.values) mean += v;
  mean /= static_cast<double>(y_in.values.size());
  double y_energy = 0.0;
  for (std::size_t k = 0; k < y_in.values.size(); ++k) {
    const auto i = static_cast<std::size_t>(y_in.grid_index[k] - y_in.grid_index.front());
    valid[i] = true;
    for (int a = 0; a < 3; ++a)
      y[static_cast<std::size_t>(a)][i] = y_in.values[k][a] - mean[a],
      y_energy += y[static_cast<std::size_t>(a)][i] * y[static_cast<std::size_t>(a)][i];
  }
  const double t_y0 = y_in.t0_s + static_cast<double>(y_in.grid_index.front()) / fs;

  // Coarse: every lag by FFT at the measurement's rate.
  std::size_t L = 1;
  while (L < n + m_coarse) L <<= 1;
  Eigen::FFT<double> fft;
  std::vector<std::vector<std::complex<double>>> Y(3), R(cols.size());
  std::vector<double> buf(L);
  for (int a = 0; a < 3; ++a) {
    std::fill(buf.begin(), buf.end(), 0.0);
    std::copy(y[static_cast<std::size_t>(a)].begin(), y[static_cast<std::size_t>(a)].end(), buf.begin());
    fft.fwd(Y[static_cast<std::size_t>(a)], buf);
  }
  Eigen::MatrixXd g_coarse = Eigen::MatrixXd::Zero(nc, nc);
  for (std::size_t c = 0; c < cols.size(); ++c) {
    std::fill(buf.begin(), buf.end(), 0.0);
    for (std::size_t m = 0; m < m_coarse; ++m) buf[m] = rf[c][m * static_cast<std::size_t>(F)];
    fft.fwd(R[c], buf);
    for (std::size_t d = 0; d < cols.size(); ++d)
      for (std::size_t m = 0; m < m_coarse; ++m)
        g_coarse(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(d)) +=
            rf[c][m * static_cast<std::size_t>(F)] * rf[d][m * static_cast<std::size_t>(F)];
  }
  if (!(g_coarse.determinant() > 0.0))
    throw dsp::InputError("time offset: the commanded acceleration is zero (nothing to correlate with)");
  const Eigen::MatrixXd g_inv = g_coarse.inverse();
  // corr[a][c][lag mod L] = Σ_n y_a[n] r_c[n − lag]
  std::vector<double> best_score(L, 0.0);
  {
    std::vector<std::vector<std::vector<double>>> corr(3, std::vector<std::vector<double>>(cols.size()));
    std::vector<std::complex<double>> prod(L);
    for (int a = 0; a < 3; ++a)
      for (std::size_t c = 0; c < cols.size(); ++c) {
        for (std::size_t k = 0; k < L; ++k) prod[k] = Y[static_cast<std::size_t>(a)][k] * std::conj(R[c][k]);
        fft.inv(corr[static_cast<std::size_t>(a)][c], prod);
      }
    Eigen::MatrixXd cm(3, nc);
    for (std::size_t k = 0; k < L; ++k) {
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < nc; ++c) cm(a, c) = corr[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)][k];
      best_score[k] = score(cm, g_inv);
    }
  }
  // Lags −(m_coarse − 1) .. n − 1 sit at k = lag mod L.
  long lag0 = 0;
  double best = -1.0;
  std::vector<double> all;
  all.reserve(n + m_coarse);
  for (long lag = -static_cast<long>(m_coarse) + 1; lag < static_cast<long>(n); ++lag) {
    const double s = best_score[static_cast<std::size_t>((lag % static_cast<long>(L) + static_cast<long>(L)) %
                                                         static_cast<long>(L))];
    all.push_back(s);
    if (s > best) best = s, lag0 = lag;
  }
  std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2), all.end());
  const double median_score = all[all.size() / 2];

  // Fine: ±2 samples on the fine grid, per block for the jackknife.
  const int span = 2 * F, n_lags = 2 * span + 1;
  std::vector<Eigen::MatrixXd> cb(static_cast<std::size_t>(kBlocks * n_lags), Eigen::MatrixXd::Zero(3, nc));
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(nc, nc);
  const std::size_t block_len = (n + kBlocks - 1) / kBlocks;
  Eigen::VectorXd r(nc);
  for (std::size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    const auto b = static_cast<std::size_t>(i / block_len);
    const long base = static_cast<long>(F) * (static_cast<long>(i) - lag0);
    for (int j = -span; j <= span; ++j) {
      const long m = base - j;
      if (m < 0 || m >= static_cast<long>(m_fine)) continue;
      for (int c = 0; c < nc; ++c) r[c] = rf[static_cast<std::size_t>(c)][static_cast<std::size_t>(m)];
      Eigen::MatrixXd& acc = cb[b * static_cast<std::size_t>(n_lags) + static_cast<std::size_t>(j + span)];
      for (int a = 0; a < 3; ++a) acc.row(a) += y[static_cast<std::size_t>(a)][i] * r.transpose();
      if (j == 0) g += r * r.transpose();
    }
  }
  if (!(g.determinant() > 0.0))
    throw dsp::InputError("time offset: the measurement does not overlap the commanded motion");
  const Eigen::MatrixXd gi = g.inverse();
  std::vector<Eigen::MatrixXd> total(static_cast<std::size_t>(n_lags), Eigen::MatrixXd::Zero(3, nc));
  for (int b = 0; b < kBlocks; ++b)
    for (int j = 0; j < n_lags; ++j) total[static_cast<std::size_t>(j)] += cb[static_cast<std::size_t>(b * n_lags + j)];
  auto tau_of = [&](double j_peak) {
    return t_y0 - ref.t_begin_s + static_cast<double>(lag0) / fs + (j_peak - span) * hf;
  };
  std::vector<double> s(static_cast<std::size_t>(n_lags));
  for (int j = 0; j < n_lags; ++j) s[static_cast<std::size_t>(j)] = score(total[static_cast<std::size_t>(j)], gi);
  const double j_hat = peak(s);
  OffsetEstimate out;
  out.peak_to_median = median_score > 0.0 ? best / median_score : std::numeric_limits<double>::infinity();
  out.offset_s = tau_of(j_hat);
  out.fine_step_s = hf;
  out.blocks = kBlocks;
  const auto j_best = static_cast<std::size_t>(std::lround(j_hat));
  out.explained = y_energy > 0.0 ? s[j_best] / y_energy : 0.0;
  const Eigen::MatrixXd gain = total[j_best] * gi;
  for (int c = 0; c < nc; ++c) out.gain.col(cols[static_cast<std::size_t>(c)]) = gain.col(c);
  std::vector<double> loo(kBlocks);
  double loo_mean = 0.0;
  for (int b = 0; b < kBlocks; ++b) {
    for (int j = 0; j < n_lags; ++j)
      s[static_cast<std::size_t>(j)] =
          score(total[static_cast<std::size_t>(j)] - cb[static_cast<std::size_t>(b * n_lags + j)], gi);
    loo[static_cast<std::size_t>(b)] = tau_of(peak(s));
    loo_mean += loo[static_cast<std::size_t>(b)] / kBlocks;
  }
  double ss = 0.0;
  for (double v : loo) ss += (v - loo_mean) * (v - loo_mean);
  out.u_s = std::sqrt((kBlocks - 1.0) / kBlocks * ss);
  return out;
}

}  // namespace eical::drivers
