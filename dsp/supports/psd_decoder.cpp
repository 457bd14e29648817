#include "dsp/supports/psd_decoder.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::supports {
namespace {

constexpr double kNoiseAlpha = 1.0 / 2000.0;  // 0.2 s memory at 10 kHz
constexpr double kLitSigmas = 30.0;
constexpr double kLitOfPeak = 0.3;
constexpr double kD2PerSigma = 1.954;  // E|i[k] − 2i[k−1] + i[k−2]| = √6·√(2/π) σ for white noise
// Second differences averaged plainly before any is clipped: a clip at 4× a mean of one or
// two values can hold the estimate near zero for seconds (it grows only as n³), and every
// noise sample is then "lit" (a strip read 73 false fixes 45 mm off at a run's start).
constexpr long kUnclippedD2 = 64;

}  // namespace

PsdDecoder::PsdDecoder(const PsdSpec& spec, const Acquisition& acquisition) {
  if (spec.measures == "x")
    axis_ = 0, cross_ = 1;
  else if (spec.measures == "y")
    axis_ = 1, cross_ = 0;
  else
    throw InputError("psd: measures must be \"x\" or \"y\", got \"" + spec.measures + "\"");
  if (!(spec.length_mm > 0.0)) throw InputError("psd: length_mm must be positive");
  centre_mm_ = spec.center_mm[axis_];
  half_length_mm_ = spec.length_mm / 2.0;
  margin_mm_ = 0.02 * spec.length_mm;  // the spot (tens of µm) clear of the ends, where u clamps
  tau_s_ = std::max(spec.lockin_tau_s, 0.0);
  lsb_v_ = acquisition.adc_lsb_volt;
  offset_counts_ = static_cast<double>(acquisition.adc_offset_counts);
}

void PsdDecoder::reset() noexcept {
  sigma_i_v_ = mean_abs_d2_ = peak_v_ = 0.0;
  seen_ = 0;
  d2_count_ = 0;
}

PsdReading PsdDecoder::step(std::int32_t i1_counts, std::int32_t i2_counts, bool missing) noexcept {
  PsdReading r;
  if (missing) return r;
  const double c[2] = {static_cast<double>(i1_counts), static_cast<double>(i2_counts)};
  const double i[2] = {(c[0] - offset_counts_) * lsb_v_, (c[1] - offset_counts_) * lsb_v_};
  // Electrode noise from second differences (robust: each clipped at 4× the running mean
  // once the mean stands on kUnclippedD2 of them). In counts, exact: a zero is a zero.
  if (seen_ >= 2) {
    for (int e = 0; e < 2; ++e) {
      double d2 = std::abs(c[e] - 2.0 * hist_[e][0] + hist_[e][1]) * lsb_v_;
      if (d2_count_ >= kUnclippedD2) d2 = std::min(d2, 4.0 * mean_abs_d2_);
      ++d2_count_;  // a plain mean at first, then exponential forgetting
      mean_abs_d2_ += std::max(kNoiseAlpha, 1.0 / static_cast<double>(d2_count_)) * (d2 - mean_abs_d2_);
    }
    sigma_i_v_ = mean_abs_d2_ / kD2PerSigma;
  }
  for (int e = 0; e < 2; ++e) hist_[e][1] = hist_[e][0], hist_[e][0] = c[e];
  if (seen_ < 1000000) ++seen_;

  const double sum = i[0] + i[1];
  r.light_v = sum;
  if (seen_ < 100 || !(sigma_i_v_ > 0.0)) return r;  // noise not known yet
  if (!(sum > kLitSigmas * std::sqrt(2.0) * sigma_i_v_)) return r;
  peak_v_ = std::max(peak_v_, sum);
  if (sum < kLitOfPeak * peak_v_) return r;
  r.u_mm = half_length_mm_ * (i[0] - i[1]) / sum;
  if (std::abs(r.u_mm) > half_length_mm_ - margin_mm_) return r;
  r.sigma_mm = 2.0 * half_length_mm_ * sigma_i_v_ * std::sqrt(i[0] * i[0] + i[1] * i[1]) / (sum * sum);
  r.valid = std::isfinite(r.u_mm) && std::isfinite(r.sigma_mm);
  return r;
}

}  // namespace eical::dsp::supports
