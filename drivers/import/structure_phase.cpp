#include "drivers/import/structure_phase.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>

namespace eical::drivers {
namespace {

// Σ over the columns of |FFT|² at bins 0 .. L/2.
std::vector<double> power(const std::vector<std::vector<double>>& cols, std::size_t L) {
  Eigen::FFT<double> fft;
  std::vector<double> buf(L), p(L / 2 + 1, 0.0);
  std::vector<std::complex<double>> X;
  for (const auto& c : cols) {
    std::fill(buf.begin(), buf.end(), 0.0);
    std::copy_n(c.begin(), std::min(c.size(), L), buf.begin());
    fft.fwd(X, buf);
    for (std::size_t k = 0; k < p.size(); ++k) p[k] += std::norm(X[k]);
  }
  return p;
}

// Moving sum over ±half bins.
std::vector<double> smoothed(const std::vector<double>& p, std::size_t half) {
  std::vector<double> prefix(p.size() + 1, 0.0), out(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) prefix[k + 1] = prefix[k] + p[k];
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::size_t lo = k > half ? k - half : 0, hi = std::min(p.size(), k + half + 1);
    out[k] = prefix[hi] - prefix[lo];
  }
  return out;
}

// The measurement's noise power per bin: its median over the bins the reference does not
// excite (0 when it leaves fewer than 16).
double noise_power(const std::vector<double>& pm, const std::vector<double>& pr, double pr_max) {
  std::vector<double> quiet;
  for (std::size_t k = 1; k < pr.size(); ++k)
    if (!(pr[k] > kExcitedFraction * pr_max)) quiet.push_back(pm[k]);
  if (quiet.size() < 16) return 0.0;
  std::nth_element(quiet.begin(), quiet.begin() + static_cast<std::ptrdiff_t>(quiet.size() / 2), quiet.end());
  return quiet[quiet.size() / 2];
}

// ln|H| at bins 0 .. L/2 where the reference excites the structure above the measurement's
// noise; elsewhere as `beyond` says (`level`: filled in by the caller). Empty when no bin is
// excited.
std::vector<double> log_magnitude(const std::vector<double>& pm, const std::vector<double>& pr, Beyond beyond,
                                  std::vector<bool>& excited) {
  const double pr_max = *std::max_element(pr.begin(), pr.end());
  const double noise = noise_power(pm, pr, pr_max);
  std::vector<double> out(pr.size(), 0.0);
  excited.assign(pr.size(), false);
  bool any = false;
  for (std::size_t k = 1; k < pr.size(); ++k)  // not DC: both means are removed
    if (pr_max > 0.0 && pr[k] > kExcitedFraction * pr_max && pm[k] > kMinSignalToNoise * noise && pm[k] > 0.0)
      out[k] = 0.5 * std::log((pm[k] - noise) / pr[k]), excited[k] = any = true;
  if (!any) return {};
  if (beyond == Beyond::level) return out;
  // Forward: each unexcited bin takes the last excited value; the ones before the first take it.
  std::size_t first = 0;
  while (!excited[first]) ++first;
  for (std::size_t k = 0; k < first; ++k) out[k] = out[first];
  for (std::size_t k = first + 1; k < out.size(); ++k)
    if (!excited[k]) out[k] = out[k - 1];
  return out;
}

}  // namespace

StructureResponse structure_response(const std::vector<std::vector<double>>& y,
                                     const std::vector<std::vector<double>>& r, double fs_hz, std::size_t L,
                                     Beyond beyond) {
  StructureResponse s;
  s.bin_hz = fs_hz / static_cast<double>(L);
  const auto half = static_cast<std::size_t>(std::ceil(kSmoothingHalfWidth_hz / s.bin_hz));
  const std::vector<double> pm = smoothed(power(y, L), half), pr = smoothed(power(r, L), half);
  std::vector<bool> excited;
  std::vector<double> log_h = log_magnitude(pm, pr, beyond, excited);
  if (log_h.empty()) return s;
  std::vector<double> sorted;
  for (std::size_t k = 0; k < log_h.size(); ++k)
    if (excited[k]) sorted.push_back(log_h[k]);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double log_level = sorted[sorted.size() / 2];
  s.level = std::exp(log_level);
  if (beyond == Beyond::level)
    for (std::size_t k = 0; k < log_h.size(); ++k)
      if (!excited[k]) log_h[k] = log_level;
  s.peak_over_level = std::exp(*std::max_element(log_h.begin(), log_h.end())) / s.level;
  // The folded real cepstrum: ln|H| even in f → its cepstrum c; the causal part (c[0],
  // 2c[n], c[L/2]) is ln H_min.
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum(L);
  for (std::size_t k = 0; k <= L / 2; ++k) spectrum[k] = log_h[k];
  for (std::size_t k = L / 2 + 1; k < L; ++k) spectrum[k] = log_h[L - k];
  std::vector<double> cep;
  fft.inv(cep, spectrum);
  for (std::size_t n = 1; n < L / 2; ++n) cep[n] *= 2.0;
  std::fill(cep.begin() + static_cast<std::ptrdiff_t>(L / 2 + 1), cep.end(), 0.0);
  fft.fwd(spectrum, cep);
  s.inverse.resize(L / 2 + 1);
  for (std::size_t k = 0; k <= L / 2; ++k) s.inverse[k] = s.level / std::exp(spectrum[k]);
  return s;
}

void apply_response(std::vector<double>& x, double dt_s, const std::vector<std::complex<double>>& w, double bin_hz) {
  std::size_t L = 1;
  while (L < 2 * x.size()) L <<= 1;  // twice: the filter's ringing does not wrap onto the signal
  Eigen::FFT<double> fft;
  std::vector<double> buf(L, 0.0);
  std::copy(x.begin(), x.end(), buf.begin());
  std::vector<std::complex<double>> X;
  fft.fwd(X, buf);
  const double df_hz = 1.0 / (static_cast<double>(L) * dt_s);
  for (std::size_t k = 0; k < L; ++k) {
    const bool negative = k > L / 2;
    const std::size_t kk = negative ? L - k : k;
    const auto idx = static_cast<std::size_t>(std::lround(static_cast<double>(kk) * df_hz / bin_hz));
    const std::complex<double> wk = idx < w.size() ? w[idx] : std::complex<double>(0.0);
    X[k] *= negative ? std::conj(wk) : wk;
  }
  fft.inv(buf, X);
  std::copy_n(buf.begin(), x.size(), x.begin());
}

}  // namespace eical::drivers
