#include "drivers/import/structure_phase.hpp"

#include "dsp/core/median.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <utility>

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
  return quiet.size() < 16 ? 0.0 : dsp::median(std::move(quiet), 0.0);
}

// ln|H| extended beyond the excited bins as `beyond` says.
std::vector<double> extended(const ResponseMagnitude& m, Beyond beyond) {
  std::vector<double> out = m.log_h;
  if (beyond == Beyond::level) {
    for (std::size_t k = 0; k < out.size(); ++k)
      if (!m.excited[k]) out[k] = std::log(m.level);
    return out;
  }
  // Each unexcited bin takes the last excited value; the ones before the first take it.
  std::size_t first = 0;
  while (!m.excited[first]) ++first;
  for (std::size_t k = 0; k < first; ++k) out[k] = out[first];
  for (std::size_t k = first + 1; k < out.size(); ++k)
    if (!m.excited[k]) out[k] = out[k - 1];
  return out;
}

}  // namespace

ResponseMagnitude response_magnitude(const std::vector<std::vector<double>>& y,
                                     const std::vector<std::vector<double>>& r, double fs_hz, std::size_t L) {
  ResponseMagnitude m;
  m.bin_hz = fs_hz / static_cast<double>(L);
  const auto half = static_cast<std::size_t>(std::ceil(kSmoothingHalfWidth_hz / m.bin_hz));
  const std::vector<double> pm = smoothed(power(y, L), half), pr = smoothed(power(r, L), half);
  const double pr_max = *std::max_element(pr.begin(), pr.end());
  const double noise = noise_power(pm, pr, pr_max);
  m.log_h.assign(pr.size(), 0.0);
  m.excited.assign(pr.size(), false);
  std::vector<double> excited_log_h;
  for (std::size_t k = 1; k < pr.size(); ++k)  // not DC: both means are removed
    if (pr_max > 0.0 && pr[k] > kExcitedFraction * pr_max && pm[k] > kMinSignalToNoise * noise && pm[k] > 0.0) {
      m.log_h[k] = 0.5 * std::log((pm[k] - noise) / pr[k]), m.excited[k] = true;
      excited_log_h.push_back(m.log_h[k]);
    }
  m.level = excited_log_h.empty() ? 0.0 : std::exp(dsp::median(std::move(excited_log_h), 0.0));
  return m;
}

StructureResponse minimum_phase_inverse(const ResponseMagnitude& m, Beyond beyond) {
  StructureResponse s;
  s.bin_hz = m.bin_hz;
  if (!(m.level > 0.0)) return s;  // nothing excited: no response to take out
  const std::vector<double> log_h = extended(m, beyond);
  const std::size_t L = 2 * (log_h.size() - 1);
  s.peak_over_level = std::exp(*std::max_element(log_h.begin(), log_h.end())) / m.level;
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
  for (std::size_t k = 0; k <= L / 2; ++k) s.inverse[k] = m.level / std::exp(spectrum[k]);
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
