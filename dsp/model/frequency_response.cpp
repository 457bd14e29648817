#include "dsp/model/frequency_response.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::model {

std::size_t segment_for(std::size_t n, double fs_hz, double df_hz, int min_averages) {
  // Half-overlapping segments: k averages need (k + 1)/2 segment lengths.
  const double longest = 2.0 * static_cast<double>(n) / static_cast<double>(min_averages + 1);
  const double wanted = fs_hz / df_hz;
  std::size_t seg = 64;
  while (static_cast<double>(seg) * 2.0 <= std::min(longest, wanted)) seg *= 2;
  return seg;
}

FrequencyResponse frequency_response(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double fs_hz,
                                     std::size_t segment) {
  FrequencyResponse out;
  std::size_t seg = 64;
  while (seg * 2 <= segment) seg *= 2;
  const auto n = static_cast<std::size_t>(std::min(u.size(), y.size()));
  if (n < seg || seg < 64) return out;
  const std::size_t nb = seg / 2 + 1;
  std::vector<double> win(seg);
  for (std::size_t i = 0; i < seg; ++i)
    win[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(seg));
  std::vector<double> suu(nb, 0.0), syy(nb, 0.0);
  std::vector<std::complex<double>> syu(nb, 0.0);
  Eigen::FFT<double> fft;
  std::vector<double> bu(seg), by(seg);
  std::vector<std::complex<double>> fu, fy;
  for (std::size_t s0 = 0; s0 + seg <= n; s0 += seg / 2) {
    double mu = 0.0, my = 0.0;
    for (std::size_t i = 0; i < seg; ++i)
      mu += u[static_cast<Eigen::Index>(s0 + i)], my += y[static_cast<Eigen::Index>(s0 + i)];
    mu /= static_cast<double>(seg), my /= static_cast<double>(seg);
    for (std::size_t i = 0; i < seg; ++i) {
      bu[i] = (u[static_cast<Eigen::Index>(s0 + i)] - mu) * win[i];
      by[i] = (y[static_cast<Eigen::Index>(s0 + i)] - my) * win[i];
    }
    fft.fwd(fu, bu), fft.fwd(fy, by);
    for (std::size_t f = 0; f < nb; ++f) {
      suu[f] += std::norm(fu[f]), syy[f] += std::norm(fy[f]);
      syu[f] += fy[f] * std::conj(fu[f]);
    }
    ++out.averages;
  }
  out.df_hz = fs_hz / static_cast<double>(seg);
  out.f_hz.resize(nb), out.h.resize(nb), out.coherence.resize(nb), out.s_uu = suu;
  for (std::size_t f = 0; f < nb; ++f) {
    out.f_hz[f] = static_cast<double>(f) * out.df_hz;
    out.h[f] = suu[f] > 0.0 ? syu[f] / suu[f] : std::complex<double>(0.0);
    out.coherence[f] = suu[f] > 0.0 && syy[f] > 0.0 ? std::min(1.0, std::norm(syu[f]) / (suu[f] * syy[f])) : 0.0;
  }
  return out;
}

}  // namespace eical::dsp::model
