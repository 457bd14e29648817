#pragma once
// The trapezoid integrators in integers, exactly: with a in Q40 m/s² and k samples per step,
//   S1 += (a + a_prev)·k          v = S1 · dt/2
//   S2 += (S1 + S1_prev)·k        x = S2 · dt²/4
// are integer additions with no rounding at all; dt (not a power of two) enters only when
// the state is read out, once per output. S1 is int64 (|v| ≤ 2⁶³·2⁻⁴⁰·dt/2 = 419 m/s at
// 10 kHz); S2 is a 128-bit accumulator held below 2⁷⁵ (x ≤ 2³⁵·dt²/4 = 86 m at 10 kHz) so
// the read-out product with a 50-bit constant fits in 128 bits. Beyond either bound the
// state saturates and the flag is set.
// Read-out with the two-stage dynamic compensation (6-38): x = S2·dt²/4 + c1·S1·dt/2 + c2·a.
#include "dsp/pipeline/dynamic_comp.hpp"
#include "dsp/pipeline/fixed_point.hpp"

#include <cstdint>

namespace eical::dsp {

inline constexpr int kOutQ = 40;  // position (m) and velocity (m/s) read-out
inline constexpr fx::Int128 kS2Bound = fx::Int128(1) << 75;

struct FixedIntegrator {
  std::int64_t a_prev_q40[3] = {0, 0, 0};
  std::int64_t s1[3] = {0, 0, 0};
  fx::Int128 s2[3] = {0, 0, 0};
  fx::QConst half_dt_s, quarter_dt2_s2, c1_half_dt_s2, c1_s, c2_s2;  // read-out constants

  FixedIntegrator() = default;
  FixedIntegrator(double dt_s, const DynamicCoefficients& c)
      : half_dt_s(fx::QConst::from(dt_s / 2.0)),
        quarter_dt2_s2(fx::QConst::from(dt_s * dt_s / 4.0, 50)),
        c1_half_dt_s2(fx::QConst::from(c.c1_s * dt_s / 2.0)),
        c1_s(fx::QConst::from(c.c1_s)),
        c2_s2(fx::QConst::from(c.c2_s2)) {}

  void start(const std::int64_t a_q40[3]) noexcept {
    for (int i = 0; i < 3; ++i) a_prev_q40[i] = a_q40[i], s1[i] = 0, s2[i] = 0;
  }

  // k_samples: samples since the last step (1, more after lost frames; kept within 0..2³⁰).
  void step(const std::int64_t a_q40[3], std::int64_t k_samples, fx::Saturation& sat) noexcept {
    if (k_samples < 0 || k_samples > (std::int64_t{1} << 30))
      sat.hit = true, k_samples = k_samples < 0 ? 0 : std::int64_t{1} << 30;
    for (int i = 0; i < 3; ++i) {
      const std::int64_t s1_new = fx::sat64((fx::Int128(a_q40[i]) + a_prev_q40[i]) * k_samples + s1[i], sat);
      s2[i] = fx::clamp128(s2[i] + (fx::Int128(s1[i]) + s1_new) * k_samples, kS2Bound, sat);
      s1[i] = s1_new;
      a_prev_q40[i] = a_q40[i];
    }
  }

  // Displacement since the start, Q40 m, with (6-38) when c1, c2 are set.
  [[nodiscard]] std::int64_t x_q40_m(int i, fx::Saturation& sat) const noexcept {
    std::int64_t x = fx::mul_wide(s2[i], fx::kAccelQ, quarter_dt2_s2, kOutQ, sat);
    x = fx::add_sat(x, fx::mul(s1[i], fx::kAccelQ, c1_half_dt_s2, kOutQ, sat), sat);
    return fx::add_sat(x, fx::mul(a_prev_q40[i], fx::kAccelQ, c2_s2, kOutQ, sat), sat);
  }
  // Velocity, Q40 m/s, with the first stage c1·a.
  [[nodiscard]] std::int64_t v_q40_mps(int i, fx::Saturation& sat) const noexcept {
    return fx::add_sat(fx::mul(s1[i], fx::kAccelQ, half_dt_s, kOutQ, sat),
                       fx::mul(a_prev_q40[i], fx::kAccelQ, c1_s, kOutQ, sat), sat);
  }
};

}  // namespace eical::dsp
