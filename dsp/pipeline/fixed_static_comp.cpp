#include "dsp/pipeline/fixed_static_comp.hpp"

#include <cmath>

namespace eical::dsp {

std::int64_t temp_q24_c(float temp_c) noexcept { return std::llround(std::ldexp(static_cast<double>(temp_c), kTempQ)); }

FixedStaticComp::FixedStaticComp(const StaticComp& c)
    : offset_counts(std::llround(c.offset_counts)),
      tc_k1_per_c(fx::QConst::from(c.tc_k1_per_c)),
      tc_bias_g_per_c(fx::QConst::from(c.tc_bias_g_per_c)),
      temp_ref_q24_c(std::llround(std::ldexp(c.temp_ref_c, kTempQ))),
      iterate(c.iterate) {
  for (int i = 0; i < 3; ++i) {
    g_per_count[i] = gain_t[i] = fx::QConst::from(c.g_per_count[i]);
    bias_q44_g[i] = bias_t_q44_g[i] = std::llround(std::ldexp(c.bias_g[i], kSensorQ));
    k2[i] = fx::QConst::from(c.k2_g_per_g2[i]);
    k3[i] = fx::QConst::from(c.k3_g_per_g3[i]);
    two_k2[i] = fx::QConst::from(2.0 * c.k2_g_per_g2[i]);
    three_k3[i] = fx::QConst::from(3.0 * c.k3_g_per_g3[i]);
    for (int j = 0; j < 3; ++j) {
      cross[i][j] = fx::QConst::from(c.cross_g_per_g(i, j));
      cross2[i][j] = fx::QConst::from(c.cross2_g_per_g2(i, j));
      cross_inverse[i][j] = fx::QConst::from(c.cross_inverse(i, j));
      to_machine_mps2_per_g[i][j] = fx::QConst::from(c.to_machine_mps2_per_g(i, j));
    }
  }
}

void FixedStaticComp::set_temperature(std::int64_t temp_q24, fx::Saturation& sat) noexcept {
  cached_temp_q24_c = temp_q24;
  const std::int64_t dt_q24 = fx::sub_sat(temp_q24, temp_ref_q24_c, sat);
  // (6-16) 1/(1 + α_k ΔT) = 1 − x + x² − x³ + x⁴ (Horner, Q60): |x| ≤ 3.5e-3 over
  // 10–50 °C, so the neglected x⁵ is below 1e-12 relative.
  const std::int64_t one = std::int64_t{1} << kCoeffQ;
  const std::int64_t x = fx::mul(dt_q24, kTempQ, tc_k1_per_c, kCoeffQ, sat);
  std::int64_t r = fx::sub_sat(x, one, sat);
  r = fx::add_sat(one, fx::mul_q(x, r, kCoeffQ, sat), sat);
  r = fx::sub_sat(fx::mul_q(x, r, kCoeffQ, sat), one, sat);
  r = fx::add_sat(one, fx::mul_q(x, r, kCoeffQ, sat), sat);
  const std::int64_t dbias_q44 = fx::mul(dt_q24, kTempQ, tc_bias_g_per_c, kSensorQ, sat);
  for (int i = 0; i < 3; ++i) {
    gain_t[i].shift = g_per_count[i].shift;
    gain_t[i].mant = fx::mul_q(g_per_count[i].mant, r, kCoeffQ, sat);
    bias_t_q44_g[i] = fx::add_sat(bias_q44_g[i], dbias_q44, sat);
  }
}

void FixedStaticComp::apply(const std::int32_t counts[3], std::int64_t temp_q24, std::int64_t out_q40_mps2[3],
                            fx::Saturation& sat) noexcept {
  if (temp_q24 != cached_temp_q24_c) set_temperature(temp_q24, sat);
  std::int64_t u[3], v[3];
  for (int i = 0; i < 3; ++i) {
    const std::int64_t c = static_cast<std::int64_t>(counts[i]) - offset_counts;
    u[i] = v[i] = fx::sub_sat(fx::mul(c, 0, gain_t[i], kSensorQ, sat), bias_t_q44_g[i], sat);  // (6-16)
  }
  if (iterate) {
    for (int it = 0; it < kStaticCompIterations; ++it) {  // (6-17) and the cross terms of (6-4)
      std::int64_t r[3];
      for (int i = 0; i < 3; ++i) {  // r = u − M(v)
        const std::int64_t v2 = fx::mul_q(v[i], v[i], kSensorQ, sat);
        const std::int64_t v3 = fx::mul_q(v2, v[i], kSensorQ, sat);
        std::int64_t m = fx::add_sat(v[i], fx::mul(v2, kSensorQ, k2[i], kSensorQ, sat), sat);
        m = fx::add_sat(m, fx::mul(v3, kSensorQ, k3[i], kSensorQ, sat), sat);
        for (int j = 0; j < 3; ++j) {
          if (j == i) continue;
          m = fx::add_sat(m, fx::mul(v[j], kSensorQ, cross[i][j], kSensorQ, sat), sat);
          m = fx::add_sat(m, fx::mul(fx::mul_q(v[i], v[j], kSensorQ, sat), kSensorQ, cross2[i][j], kSensorQ, sat), sat);
        }
        r[i] = fx::sub_sat(u[i], m, sat);
      }
      std::int64_t next[3];
      for (int i = 0; i < 3; ++i) {  // v + (K⁻¹ − diag(s))·r
        const std::int64_t slope =
            fx::add_sat(fx::mul(v[i], kSensorQ, two_k2[i], kSensorQ, sat),
                        fx::mul(fx::mul_q(v[i], v[i], kSensorQ, sat), kSensorQ, three_k3[i], kSensorQ, sat), sat);
        std::int64_t d = fx::sub_sat(0, fx::mul_q(slope, r[i], kSensorQ, sat), sat);
        for (int j = 0; j < 3; ++j)
          d = fx::add_sat(d, fx::mul(r[j], kSensorQ, cross_inverse[i][j], kSensorQ, sat), sat);
        next[i] = fx::add_sat(v[i], d, sat);
      }
      for (int i = 0; i < 3; ++i) v[i] = next[i];
    }
  }
  for (int i = 0; i < 3; ++i) {  // (6-18) into machine axes, g → m/s²
    std::int64_t a = 0;
    for (int j = 0; j < 3; ++j)
      a = fx::add_sat(a, fx::mul(v[j], kSensorQ, to_machine_mps2_per_g[i][j], fx::kAccelQ, sat), sat);
    out_q40_mps2[i] = a;
  }
}

}  // namespace eical::dsp
