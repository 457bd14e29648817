#include "drivers/import/time_offset.hpp"

#include "drivers/import/structure_phase.hpp"
#include "dsp/core/error.hpp"
#include "sim/sensor/pt2.hpp"

#include <Eigen/Eigenvalues>
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

// The Moore–Penrose inverse of a reference Gram matrix, or an empty matrix when the
// reference is zero. A pseudo-inverse, not an inverse: a test along a diagonal (a CoreXY's
// belt test) moves x and y together, so their columns are collinear and the Gram matrix
// singular; the score then is that of the one direction the motion spans, and the gain the
// minimum-norm split of it over the axes.
Eigen::MatrixXd gram_pseudo_inverse(const Eigen::MatrixXd& g) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(g);
  const Eigen::VectorXd& ev = es.eigenvalues();
  const double largest = ev.size() > 0 ? ev.maxCoeff() : 0.0;
  if (!(largest > 0.0) || !std::isfinite(largest)) return {};
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(ev.size());
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (ev[i] > 1e-9 * largest) inv[i] = 1.0 / ev[i];
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

using Columns = std::vector<std::vector<double>>;  // per reference column (or axis), its samples

// Throws on unusable inputs; the machine axes the reference moves (its columns).
std::vector<int> check_inputs(const MeasuredSeries& y_in, const ReferenceSignal& ref, int F) {
  if (!(y_in.fs_hz > 0.0) || y_in.grid_index.size() != y_in.values.size() || y_in.values.size() < 16)
    throw dsp::InputError("time offset: the measurement needs a rate and at least 16 samples");
  if (!(ref.t_end_s > ref.t_begin_s) || !ref.accel)
    throw dsp::InputError("time offset: the reference has no time span");
  if (F < 1) throw dsp::InputError("time offset: oversample must be >= 1");
  std::vector<int> cols;
  for (int j = 0; j < 3; ++j)
    if (ref.moving[j] != 0.0) cols.push_back(j);
  if (cols.empty()) throw dsp::InputError("time offset: the reference moves no axis");
  return cols;
}

// The reference on the fine grid (step hf) through the sensor's low-pass, mean removed.
Columns fine_reference(const ReferenceSignal& ref, const std::vector<int>& cols, double hf) {
  const auto m_fine = static_cast<std::size_t>(std::floor((ref.t_end_s - ref.t_begin_s) / hf)) + 1;
  Columns rf(cols.size(), std::vector<double>(m_fine));
  std::vector<sim::Pt2> lp;
  if (ref.sensor_f0_hz > 0.0)
    for (std::size_t c = 0; c < cols.size(); ++c) lp.emplace_back(ref.sensor_f0_hz, ref.sensor_zeta, hf);
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
  return rf;
}

// The reference at the measurement's rate: every F-th fine sample, m_coarse of them.
Columns coarse_columns(const Columns& rf, int F, std::size_t m_coarse) {
  Columns out(rf.size(), std::vector<double>(m_coarse));
  for (std::size_t c = 0; c < rf.size(); ++c)
    for (std::size_t m = 0; m < m_coarse; ++m) out[c][m] = rf[c][m * static_cast<std::size_t>(F)];
  return out;
}

// The measurement on its grid, mean removed, lost frames zero.
struct Grid {
  Columns y;  // per sensor axis
  std::vector<bool> valid;
  double energy = 0.0;  // Σ y²
  double t0_s = 0.0;    // recorder time of the grid's first sample
};

Grid measurement_grid(const MeasuredSeries& y_in) {
  const auto n = static_cast<std::size_t>(y_in.grid_index.back() - y_in.grid_index.front()) + 1;
  Grid g;
  g.y.assign(3, std::vector<double>(n, 0.0));
  g.valid.assign(n, false);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : y_in.values) mean += v;
  mean /= static_cast<double>(y_in.values.size());
  for (std::size_t k = 0; k < y_in.values.size(); ++k) {
    const auto i = static_cast<std::size_t>(y_in.grid_index[k] - y_in.grid_index.front());
    g.valid[i] = true;
    for (int a = 0; a < 3; ++a)
      g.y[static_cast<std::size_t>(a)][i] = y_in.values[k][a] - mean[a],
      g.energy += g.y[static_cast<std::size_t>(a)][i] * g.y[static_cast<std::size_t>(a)][i];
  }
  g.t0_s = y_in.t0_s + static_cast<double>(y_in.grid_index.front()) / y_in.fs_hz;
  return g;
}

// The score at every lag mod L (L ≥ n + m_coarse, a power of 2), by FFT at the
// measurement's rate (every F-th fine reference sample).
std::vector<double> coarse_scores(const Columns& y, const Columns& rf, int F, std::size_t m_coarse, std::size_t L) {
  const auto nc = static_cast<int>(rf.size());
  Eigen::FFT<double> fft;
  std::vector<std::vector<std::complex<double>>> Y(3), R(rf.size());
  std::vector<double> buf(L);
  for (int a = 0; a < 3; ++a) {
    std::fill(buf.begin(), buf.end(), 0.0);
    std::copy(y[static_cast<std::size_t>(a)].begin(), y[static_cast<std::size_t>(a)].end(), buf.begin());
    fft.fwd(Y[static_cast<std::size_t>(a)], buf);
  }
  Eigen::MatrixXd g_coarse = Eigen::MatrixXd::Zero(nc, nc);
  for (std::size_t c = 0; c < rf.size(); ++c) {
    std::fill(buf.begin(), buf.end(), 0.0);
    for (std::size_t m = 0; m < m_coarse; ++m) buf[m] = rf[c][m * static_cast<std::size_t>(F)];
    fft.fwd(R[c], buf);
    for (std::size_t d = 0; d < rf.size(); ++d)
      for (std::size_t m = 0; m < m_coarse; ++m)
        g_coarse(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(d)) +=
            rf[c][m * static_cast<std::size_t>(F)] * rf[d][m * static_cast<std::size_t>(F)];
  }
  const Eigen::MatrixXd g_inv = gram_pseudo_inverse(g_coarse);
  if (g_inv.size() == 0)
    throw dsp::InputError("time offset: the commanded acceleration is zero (nothing to correlate with)");
  // corr[a][c][lag mod L] = Σ_n y_a[n] r_c[n − lag]
  std::vector<std::vector<std::vector<double>>> corr(3, std::vector<std::vector<double>>(rf.size()));
  std::vector<std::complex<double>> prod(L);
  for (int a = 0; a < 3; ++a)
    for (std::size_t c = 0; c < rf.size(); ++c) {
      for (std::size_t k = 0; k < L; ++k) prod[k] = Y[static_cast<std::size_t>(a)][k] * std::conj(R[c][k]);
      fft.inv(corr[static_cast<std::size_t>(a)][c], prod);
    }
  std::vector<double> scores(L, 0.0);
  Eigen::MatrixXd cm(3, nc);
  for (std::size_t k = 0; k < L; ++k) {
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < nc; ++c) cm(a, c) = corr[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)][k];
    scores[k] = score(cm, g_inv);
  }
  return scores;
}

// The coarse peak over the lags −(m_coarse − 1) .. n − 1 (at k = lag mod L) and the median score.
struct CoarsePeak {
  long lag = 0;
  double best = -1.0, median = 0.0;
};

CoarsePeak coarse_peak(const std::vector<double>& scores, std::size_t n, std::size_t m_coarse) {
  const auto L = static_cast<long>(scores.size());
  CoarsePeak p;
  std::vector<double> all;
  all.reserve(n + m_coarse);
  for (long lag = -static_cast<long>(m_coarse) + 1; lag < static_cast<long>(n); ++lag) {
    const double s = scores[static_cast<std::size_t>((lag % L + L) % L)];
    all.push_back(s);
    if (s > p.best) p.best = s, p.lag = lag;
  }
  std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(all.size() / 2), all.end());
  p.median = all[all.size() / 2];
  return p;
}

// Fine: the correlations at ±span fine lags about the coarse peak, per block of the
// measurement (for the jackknife), and the reference's Gram matrix at the peak.
struct FineCorrelations {
  int span = 0, n_lags = 0;
  std::vector<Eigen::MatrixXd> block;  // [b · n_lags + j]: 3 × columns
  std::vector<Eigen::MatrixXd> total;  // [j]: summed over the blocks
  Eigen::MatrixXd g_inv;
};

FineCorrelations fine_correlations(const Grid& grid, const Columns& rf, int F, long lag0) {
  const auto nc = static_cast<int>(rf.size());
  const std::size_t n = grid.valid.size(), m_fine = rf.front().size();
  FineCorrelations fc;
  fc.span = 2 * F, fc.n_lags = 2 * fc.span + 1;
  const int span = fc.span, n_lags = fc.n_lags;
  fc.block.assign(static_cast<std::size_t>(kBlocks * n_lags), Eigen::MatrixXd::Zero(3, nc));
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(nc, nc);
  const std::size_t block_len = (n + kBlocks - 1) / kBlocks;
  Eigen::VectorXd r(nc);
  for (std::size_t i = 0; i < n; ++i) {
    if (!grid.valid[i]) continue;
    const auto b = static_cast<std::size_t>(i / block_len);
    const long base = static_cast<long>(F) * (static_cast<long>(i) - lag0);
    for (int j = -span; j <= span; ++j) {
      const long m = base - j;
      if (m < 0 || m >= static_cast<long>(m_fine)) continue;
      for (int c = 0; c < nc; ++c) r[c] = rf[static_cast<std::size_t>(c)][static_cast<std::size_t>(m)];
      Eigen::MatrixXd& acc = fc.block[b * static_cast<std::size_t>(n_lags) + static_cast<std::size_t>(j + span)];
      for (int a = 0; a < 3; ++a) acc.row(a) += grid.y[static_cast<std::size_t>(a)][i] * r.transpose();
      if (j == 0) g += r * r.transpose();
    }
  }
  fc.g_inv = gram_pseudo_inverse(g);
  if (fc.g_inv.size() == 0) throw dsp::InputError("time offset: the measurement does not overlap the commanded motion");
  fc.total.assign(static_cast<std::size_t>(n_lags), Eigen::MatrixXd::Zero(3, nc));
  for (int b = 0; b < kBlocks; ++b)
    for (int j = 0; j < n_lags; ++j)
      fc.total[static_cast<std::size_t>(j)] += fc.block[static_cast<std::size_t>(b * n_lags + j)];
  return fc;
}

// The offset at a (fractional) fine lag index j_peak: base_s + (j_peak − span)·hf.
struct LagTime {
  double base_s = 0.0, hf = 0.0;
  int span = 0;
  [[nodiscard]] double operator()(double j_peak) const { return base_s + (j_peak - span) * hf; }
};

// Block jackknife: the fine peak with each block left out once; u = √((K−1)/K · Σ (τ_−k − τ̄)²).
double jackknife_u(const FineCorrelations& fc, const LagTime& tau_of) {
  std::vector<double> s(static_cast<std::size_t>(fc.n_lags));
  std::vector<double> loo(kBlocks);
  double loo_mean = 0.0;
  for (int b = 0; b < kBlocks; ++b) {
    for (int j = 0; j < fc.n_lags; ++j)
      s[static_cast<std::size_t>(j)] = score(
          fc.total[static_cast<std::size_t>(j)] - fc.block[static_cast<std::size_t>(b * fc.n_lags + j)], fc.g_inv);
    loo[static_cast<std::size_t>(b)] = tau_of(peak(s));
    loo_mean += loo[static_cast<std::size_t>(b)] / kBlocks;
  }
  double ss = 0.0;
  for (double v : loo) ss += (v - loo_mean) * (v - loo_mean);
  return std::sqrt((kBlocks - 1.0) / kBlocks * ss);
}

// The offset from the measurement with the structure's response taken out, the response
// extended beyond the excited band as `beyond` says (structure_phase.hpp).
struct RigidOffset {
  CoarsePeak coarse;
  double offset_s = 0.0, u_s = 0.0, j_hat = 0.0, structure_peak = 0.0;
};

RigidOffset rigid_offset(const Grid& grid, const Columns& rf, int F, std::size_t m_coarse, std::size_t L, double fs,
                         double t_begin_s, const ResponseMagnitude& magnitude, Beyond beyond) {
  const StructureResponse structure = minimum_phase_inverse(magnitude, beyond);
  Grid rigid = grid;
  if (!structure.inverse.empty())
    for (auto& y : rigid.y) apply_response(y, 1.0 / fs, structure.inverse, structure.bin_hz);
  RigidOffset r;
  r.structure_peak = structure.peak_over_level;
  r.coarse = coarse_peak(coarse_scores(rigid.y, rf, F, m_coarse, L), grid.valid.size(), m_coarse);
  const FineCorrelations fc = fine_correlations(rigid, rf, F, r.coarse.lag);
  const LagTime tau_of{grid.t0_s - t_begin_s + static_cast<double>(r.coarse.lag) / fs, 1.0 / (fs * F), fc.span};
  std::vector<double> s(static_cast<std::size_t>(fc.n_lags));
  for (int j = 0; j < fc.n_lags; ++j)
    s[static_cast<std::size_t>(j)] = score(fc.total[static_cast<std::size_t>(j)], fc.g_inv);
  r.j_hat = peak(s);
  r.offset_s = tau_of(r.j_hat);
  r.u_s = jackknife_u(fc, tau_of);
  return r;
}

}  // namespace

OffsetEstimate estimate_offset(const MeasuredSeries& measured, const ReferenceSignal& reference, int oversample) {
  const std::vector<int> cols = check_inputs(measured, reference, oversample);
  const double fs = measured.fs_hz, hf = 1.0 / (fs * oversample);
  const Columns rf = fine_reference(reference, cols, hf);
  const std::size_t m_coarse = (rf.front().size() - 1) / static_cast<std::size_t>(oversample) + 1;
  const Grid grid = measurement_grid(measured);
  std::size_t L = 1;
  while (L < grid.valid.size() + m_coarse) L <<= 1;
  // The response beyond the band is not measured: the estimate holds its edges, and the
  // other guess (the median level) bounds what that choice moves the offset by, a
  // rectangular distribution of that half-width (GUM 4.3.7) beside the jackknife's.
  const ResponseMagnitude magnitude = response_magnitude(grid.y, coarse_columns(rf, oversample, m_coarse), fs, L);
  const RigidOffset held =
      rigid_offset(grid, rf, oversample, m_coarse, L, fs, reference.t_begin_s, magnitude, Beyond::hold_edges);
  const RigidOffset level =
      rigid_offset(grid, rf, oversample, m_coarse, L, fs, reference.t_begin_s, magnitude, Beyond::level);
  const double extension_s = held.offset_s - level.offset_s;
  OffsetEstimate out;
  out.peak_to_median =
      held.coarse.median > 0.0 ? held.coarse.best / held.coarse.median : std::numeric_limits<double>::infinity();
  out.offset_s = held.offset_s;
  out.u_s = std::sqrt(held.u_s * held.u_s + extension_s * extension_s / 3.0);
  out.u_extension_s = std::abs(extension_s) / std::sqrt(3.0);
  out.fine_step_s = hf;
  out.blocks = kBlocks;
  out.structure_peak = held.structure_peak;
  // The gain and the explained fraction from the measurement as it is, at the offset.
  const FineCorrelations whole = fine_correlations(grid, rf, oversample, held.coarse.lag);
  const auto j_best = static_cast<std::size_t>(std::lround(held.j_hat));
  out.explained = grid.energy > 0.0 ? score(whole.total[j_best], whole.g_inv) / grid.energy : 0.0;
  const Eigen::MatrixXd gain = whole.total[j_best] * whole.g_inv;
  for (std::size_t c = 0; c < cols.size(); ++c) out.gain.col(cols[c]) = gain.col(static_cast<Eigen::Index>(c));
  return out;
}

}  // namespace eical::drivers
