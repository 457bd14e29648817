#include "sim/daq/decimation_filter.hpp"

#include "dsp/core/error.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace eical::sim {

DecimationFilter::DecimationFilter(int oversample, double delay_samples, double passband_fs,
                                   double design_delay_samples)
    : ov_(oversample) {
  if (oversample < 1) throw dsp::InputError("DAQ filter: oversample must be >= 1");
  if (!(delay_samples >= 0.0)) throw dsp::InputError("DAQ filter: delay must not be negative");
  const double delay_in = delay_samples * oversample;
  const long m_design = std::lround(design_delay_samples * oversample);
  const long m = std::max(0L, std::min(m_design, static_cast<long>(std::floor(delay_in))));
  shift_ = static_cast<long>(std::floor(delay_in));
  frac_ = delay_in - static_cast<double>(shift_);
  taps_half_.assign(static_cast<std::size_t>(m) + 1, 0.0);
  if (m == 0 || oversample == 1) {  // no room for a filter: a pure delay
    taps_half_.assign(1, 1.0);
    return;
  }
  // Kaiser design: transition width from the length and the attenuation (Kaiser's formula),
  // cut-off half a transition above the pass-band edge.
  const double atten_db = 90.0, beta = 0.1102 * (atten_db - 8.7);
  const double transition_out =
      (atten_db - 8.0) / (2.285 * 2.0 * std::numbers::pi * static_cast<double>(2 * m)) * oversample;
  const double fc = (passband_fs + transition_out / 2.0) / oversample;  // cycles per internal sample
  const double i0_beta = std::cyl_bessel_i(0.0, beta);
  double sum = 0.0;
  for (long j = 0; j <= m; ++j) {
    const double x = static_cast<double>(j);
    const double sinc = j == 0 ? 2.0 * fc : std::sin(2.0 * std::numbers::pi * fc * x) / (std::numbers::pi * x);
    const double r = x / static_cast<double>(m);
    const double w = std::cyl_bessel_i(0.0, beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / i0_beta;
    taps_half_[static_cast<std::size_t>(j)] = sinc * w;
    sum += (j == 0 ? 1.0 : 2.0) * sinc * w;
  }
  for (double& t : taps_half_) t /= sum;
}

double DecimationFilter::gain(double f_over_fs) const {
  double g = taps_half_[0];
  for (std::size_t j = 1; j < taps_half_.size(); ++j)
    g += 2.0 * taps_half_[j] * std::cos(2.0 * std::numbers::pi * f_over_fs / ov_ * static_cast<double>(j));
  return g;
}

void DecimationFilter::apply(const std::vector<double>& in, double* out, std::size_t n_out) const {
  if (in.empty()) throw dsp::InputError("DAQ filter: no input");
  const long m = static_cast<long>(taps_half_.size()) - 1;
  const long n_in = static_cast<long>(in.size());
  // The input as the filter sees it: x(k − frac) with the ends held. A whole-sample delay
  // (the nominal 38.8 samples at 10x) is read in place; a fractional one is interpolated
  // into a copy first.
  std::vector<double> shifted;
  if (frac_ != 0.0) {
    shifted.resize(in.size());
    shifted[0] = in[0];
    for (std::size_t k = 1; k < in.size(); ++k) shifted[k] = (1.0 - frac_) * in[k] + frac_ * in[k - 1];
  }
  const std::vector<double>& x = frac_ != 0.0 ? shifted : in;
  // Where the input is constant over all taps the output is that constant (DC gain 1): a PSD
  // strip is dark most of the time, a sensor at rest without vibration is constant.
  // changes[k] counts the value changes up to k.
  std::vector<std::uint32_t> changes(x.size(), 0);
  for (std::size_t k = 1; k < x.size(); ++k) changes[k] = changes[k - 1] + (x[k] != x[k - 1] ? 1u : 0u);
  // Symmetric taps folded: h[0]·x[c] + Σ h[j]·(x[c−j] + x[c+j]), as Eigen expressions,
  // which are explicitly vectorised (a plain loop is not, without -ffast-math).
  const Eigen::Map<const Eigen::VectorXd> h(taps_half_.data() + 1, m);
  auto filter_at = [&](const double* centre) {
    const Eigen::Map<const Eigen::VectorXd> before(centre - m, m), after(centre + 1, m);
    return taps_half_[0] * centre[0] + h.dot(before.reverse() + after);
  };
  std::vector<double> edge(static_cast<std::size_t>(2 * m + 1));
  for (std::size_t n = 0; n < n_out; ++n) {
    const long c = static_cast<long>(n) * ov_ - shift_;
    const long lo = std::clamp(c - m, 0L, n_in - 1), hi = std::clamp(c + m, 0L, n_in - 1);
    if (changes[static_cast<std::size_t>(hi)] == changes[static_cast<std::size_t>(lo)]) {
      out[n] = x[static_cast<std::size_t>(lo)];
    } else if (c - m >= 0 && c + m < n_in) {
      out[n] = filter_at(x.data() + c);
    } else {  // near the ends: the held values in a small copy
      for (long j = -m; j <= m; ++j)
        edge[static_cast<std::size_t>(j + m)] = x[static_cast<std::size_t>(std::clamp(c + j, 0L, n_in - 1))];
      out[n] = filter_at(edge.data() + m);
    }
  }
}

double DecimationFilter::output_at(const std::vector<double>& x, long c) const {
  const long m = static_cast<long>(taps_half_.size()) - 1;
  const long n_in = static_cast<long>(x.size());
  auto at = [&](long k) { return x[static_cast<std::size_t>(std::clamp(k, 0L, n_in - 1))]; };
  double y = taps_half_[0] * at(c);
  for (long j = 1; j <= m; ++j) y += taps_half_[static_cast<std::size_t>(j)] * (at(c - j) + at(c + j));
  return y;
}

void DecimationFilter::apply_at(const std::vector<double>& in, const double* positions, double* out,
                                std::size_t n_out) const {
  if (in.empty()) throw dsp::InputError("DAQ filter: no input");
  std::vector<double> shifted;
  if (frac_ != 0.0) {
    shifted.resize(in.size());
    shifted[0] = in[0];
    for (std::size_t k = 1; k < in.size(); ++k) shifted[k] = (1.0 - frac_) * in[k] + frac_ * in[k - 1];
  }
  const std::vector<double>& x = frac_ != 0.0 ? shifted : in;
  for (std::size_t n = 0; n < n_out; ++n) {
    const double c = positions[n] * ov_ - static_cast<double>(shift_);
    const double c0 = std::floor(c), w = c - c0;
    const long k = static_cast<long>(c0);
    out[n] = w == 0.0 ? output_at(x, k) : (1.0 - w) * output_at(x, k) + w * output_at(x, k + 1);
  }
}

}  // namespace eical::sim
