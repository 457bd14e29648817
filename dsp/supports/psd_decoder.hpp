#pragma once
// PSD strip → position fix (ch. 5.3, Bild 5-2). The two electrodes share the photocurrent
// by the spot's position u along the strip; normalising by their sum makes u independent
// of the light's intensity and of how much of the spot falls on the strip:
//   u = (L/2) · (i1 − i2) / (i1 + i2)        (i1 is the electrode at the +u end)
// (that electrode order is what the sample runs in tests/data show: checked against
// their reference instrument). A sample is a fix when the strip is lit — the sum above
// both 30 σ of its noise and 30 % of the brightest sum seen — and the spot is clear of
// the strip's ends. Its σ follows from the electrodes' noise by propagation:
//   σ_u = L σ_i √(i1² + i2²) / (i1 + i2)²
// σ_i is tracked from second differences of the outputs (a spot moving at constant speed
// changes them linearly), clipped so that the edges of a crossing do not inflate it.
// The lock-in amplifier lags by its time constant τ: position = centre + u + τ·v.
#include "dsp/core/run_meta.hpp"

#include <cstdint>

namespace eical::dsp::supports {

struct PsdReading {
  bool valid = false;
  double u_mm = 0.0;      // along the strip from its centre (lock-in lag not yet removed)
  double sigma_mm = 0.0;  // noise of u
  double light_v = 0.0;   // i1 + i2
};

class PsdDecoder {
 public:
  PsdDecoder() = default;
  // Throws InputError for a strip that measures neither x nor y or has no length.
  PsdDecoder(const PsdSpec& spec, const Acquisition& acquisition);

  [[nodiscard]] int axis() const noexcept { return axis_; }  // machine axis measured
  [[nodiscard]] int cross_axis() const noexcept { return cross_; }
  [[nodiscard]] double centre_mm() const noexcept { return centre_mm_; }  // of the strip along axis()
  [[nodiscard]] double lockin_tau_s() const noexcept { return tau_s_; }
  [[nodiscard]] double noise_v() const noexcept { return sigma_i_v_; }

  PsdReading step(std::int32_t i1_counts, std::int32_t i2_counts, bool missing) noexcept;
  void reset() noexcept;

 private:
  int axis_ = 0, cross_ = 1;
  double centre_mm_ = 0.0, half_length_mm_ = 5.0, margin_mm_ = 0.2, tau_s_ = 0.0;
  double lsb_v_ = 1.0, offset_counts_ = 0.0;
  double sigma_i_v_ = 0.0;  // tracked electrode noise
  double mean_abs_d2_ = 0.0;
  double peak_v_ = 0.0;
  double hist_[2][2] = {{0, 0}, {0, 0}};  // last two values per electrode, counts
  int seen_ = 0;
  long d2_count_ = 0;
};

}  // namespace eical::dsp::supports
