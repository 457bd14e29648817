#pragma once
// The static compensation (static_comp.hpp) in Q-format integers: the same formulas,
// (6-16) temperature-compensated scale and bias, the (6-4)/(6-17) model inversion by three
// approximate Newton steps, and the (6-18) correction into machine axes.
//
// Q formats and why those widths
//  * temperature Q24 °C: every float case temperature with |T| ≥ 0.5 °C (float ulp ≥ 2⁻²⁴
//    there) is held exactly, so the fixed path sees the same temperature as the double path.
//  * sensor-axis acceleration Q44 g (LSB 5.7e-14 g, range ±2¹⁹ g): a rounding there is
//    5.6e-13 m/s²; v² and v³ of the ±8 g a 24-bit ADC can reach stay inside int64 (v³ of
//    more than ±2⁶ g saturates — beyond any sensor's range, and flagged).
//  * machine-axis acceleration Q40 m/s² (LSB 9.1e-13 m/s², range ±2²³ m/s²): the rest-window
//    bias is rounded once and then acts as a constant for the whole run; ½·½LSB·(10 s)² =
//    2.3e-11 m, 40 times below the 1 nm the fixed path must meet over 10 s.
//  * constants (gains, k2, k3, cross terms, matrix): 62-bit mantissas with their own shift
//    (fx::QConst) — they hold the configured double exactly.
#include "dsp/core/run_meta.hpp"
#include "dsp/pipeline/fixed_point.hpp"
#include "dsp/pipeline/static_comp.hpp"

#include <cstdint>

namespace eical::dsp {

inline constexpr int kTempQ = 24;    // °C
inline constexpr int kSensorQ = 44;  // g, sensor axes
inline constexpr int kCoeffQ = 60;   // dimensionless series in the temperature terms

// A float case temperature in Q24 °C (exact for |T| ≥ 0.5 °C).
[[nodiscard]] std::int64_t temp_q24_c(float temp_c) noexcept;

struct FixedStaticComp {
  fx::QConst g_per_count[3];  // lsb / k1 at the reference temperature
  std::int64_t offset_counts = 0;
  std::int64_t bias_q44_g[3] = {0, 0, 0};
  fx::QConst tc_k1_per_c, tc_bias_g_per_c;
  std::int64_t temp_ref_q24_c = 0;
  fx::QConst k2[3], k3[3], two_k2[3], three_k3[3], cross[3][3], cross2[3][3], cross_inverse[3][3];
  bool iterate = false;
  fx::QConst to_machine_mps2_per_g[3][3];
  // Coefficients at the last temperature (recomputed when the reading changes).
  std::int64_t cached_temp_q24_c = fx::kMin64;  // none yet
  fx::QConst gain_t[3];
  std::int64_t bias_t_q44_g[3] = {0, 0, 0};

  FixedStaticComp() = default;
  explicit FixedStaticComp(const StaticComp& c);

  // Counts and a Q24 temperature → specific force in machine axes, Q40 m/s².
  void apply(const std::int32_t counts[3], std::int64_t temp_q24, std::int64_t out_q40_mps2[3],
             fx::Saturation& sat) noexcept;

 private:
  void set_temperature(std::int64_t temp_q24, fx::Saturation& sat) noexcept;
};

}  // namespace eical::dsp
