#pragma once
// Q-format integer arithmetic for the fixed-point path (as a DSP on the DAQ card would run
// the static compensation and the integrators). Bit-exact and deterministic: integers
// only per sample; doubles only when a configuration is turned into constants.
//
// Conventions
//  * A signal in Qn is an int64 v meaning v·2⁻ⁿ in its unit (names say both: `a_q40_mps2`).
//  * Products go into a 128-bit accumulator (a DSP's wide accumulator; here __int128) and
//    are rounded once, to nearest with ties away from zero (symmetric: no drift from
//    rounding a signal that is symmetric about zero).
//  * A constant is a QConst: a mantissa of `bits` significant bits and its own shift,
//    chosen when the configuration is loaded (block-floating constants), so a scale of
//    9.7e-7 g/count keeps the same relative precision (2⁻⁶¹) as a gain of 9.81.
//  * Overflow never wraps: results saturate at the int64 range (or a stated bound) and
//    set a sticky flag that the pipeline reports (quality flag fixed_saturated).
#include <cmath>
#include <cstdint>
#include <limits>

namespace eical::dsp::fx {

__extension__ using Int128 = __int128;

// The acceleration format between the static compensation and the integrators, m/s²
// (reasons in fixed_static_comp.hpp).
inline constexpr int kAccelQ = 40;

inline constexpr std::int64_t kMax64 = std::numeric_limits<std::int64_t>::max();
inline constexpr std::int64_t kMin64 = std::numeric_limits<std::int64_t>::min();

// Sticky saturation flag: set by any operation that had to clamp.
struct Saturation {
  bool hit = false;
};

[[nodiscard]] inline std::int64_t sat64(Int128 v, Saturation& s) noexcept {
  if (v > kMax64) return s.hit = true, kMax64;
  if (v < kMin64) return s.hit = true, kMin64;
  return static_cast<std::int64_t>(v);
}

[[nodiscard]] inline Int128 clamp128(Int128 v, Int128 bound, Saturation& s) noexcept {
  if (v > bound) return s.hit = true, bound;
  if (v < -bound) return s.hit = true, -bound;
  return v;
}

[[nodiscard]] inline std::int64_t add_sat(std::int64_t a, std::int64_t b, Saturation& s) noexcept {
  std::int64_t r;
  if (__builtin_add_overflow(a, b, &r)) return s.hit = true, a > 0 ? kMax64 : kMin64;
  return r;
}

[[nodiscard]] inline std::int64_t sub_sat(std::int64_t a, std::int64_t b, Saturation& s) noexcept {
  std::int64_t r;
  if (__builtin_sub_overflow(a, b, &r)) return s.hit = true, a >= 0 ? kMax64 : kMin64;
  return r;
}

// v·2⁻ˢʰⁱᶠᵗ rounded to nearest, ties away from zero; shift ≤ 0 multiplies (saturating at
// ±2¹²⁶). |v| must stay below 2¹²⁶ (every caller's products do, by their bounds).
[[nodiscard]] inline Int128 shift_round(Int128 v, int shift, Saturation& s) noexcept {
  if (shift > 0) {
    if (shift >= 127) return 0;
    const Int128 half = Int128(1) << (shift - 1);
    return v >= 0 ? (v + half) >> shift : -((-v + half) >> shift);
  }
  const Int128 bound = Int128(1) << 126;
  for (int k = 0; k < -shift; ++k) {
    if (v > bound / 2 || v < -bound / 2) return s.hit = true, v > 0 ? bound : -bound;
    v *= 2;
  }
  return v;
}

// Rounded quotient num / den (den > 0), ties away from zero.
[[nodiscard]] inline Int128 div_round(Int128 num, Int128 den) noexcept {
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

// A constant x ≈ mant·2⁻ˢʰⁱᶠᵗ with |mant| < 2^bits (bits ≤ 62).
struct QConst {
  std::int64_t mant = 0;
  int shift = 0;

  [[nodiscard]] static QConst from(double x, int bits = 62) noexcept {
    if (x == 0.0 || !std::isfinite(x)) return {};
    int e = 0;
    (void)std::frexp(x, &e);  // |x| = f·2^e, f in [0.5, 1)
    const int shift = bits - e;
    return {static_cast<std::int64_t>(std::llround(std::ldexp(x, shift))), shift};
  }
  [[nodiscard]] double value() const noexcept { return std::ldexp(static_cast<double>(mant), -shift); }
};

// value (Q`in_q`) × c → Q`out_q`, one rounding, saturated to int64.
[[nodiscard]] inline std::int64_t mul(std::int64_t value, int in_q, const QConst& c, int out_q,
                                      Saturation& s) noexcept {
  return sat64(shift_round(Int128(value) * c.mant, c.shift + in_q - out_q, s), s);
}

// value (Q`in_q`, a 128-bit accumulator below 2⁷⁵ in magnitude) × c (mantissa < 2⁵⁰) → Q`out_q`.
[[nodiscard]] inline std::int64_t mul_wide(Int128 value, int in_q, const QConst& c, int out_q, Saturation& s) noexcept {
  return sat64(shift_round(value * c.mant, c.shift + in_q - out_q, s), s);
}

// Two Q`q` signals multiplied, back in Q`q`.
[[nodiscard]] inline std::int64_t mul_q(std::int64_t a, std::int64_t b, int q, Saturation& s) noexcept {
  return sat64(shift_round(Int128(a) * b, q, s), s);
}

[[nodiscard]] inline double to_double(std::int64_t v, int q) noexcept { return std::ldexp(static_cast<double>(v), -q); }

}  // namespace eical::dsp::fx
