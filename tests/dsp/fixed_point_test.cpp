// Q-format primitives and the fixed-point stages: rounding, saturation instead of
// wrap-around, the sticky flag, and agreement of FixedStaticComp with StaticComp.
#include "dsp/pipeline/fixed_point.hpp"
#include "dsp/pipeline/fixed_integrator.hpp"
#include "dsp/pipeline/fixed_static_comp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace eical::dsp {
namespace {

TEST(FixedPoint, RoundsToNearestTiesAwayFromZero) {
  fx::Saturation s;
  EXPECT_EQ(fx::shift_round(3, 1, s), 2);    // 1.5 → 2
  EXPECT_EQ(fx::shift_round(-3, 1, s), -2);  // −1.5 → −2 (symmetric)
  EXPECT_EQ(fx::shift_round(5, 2, s), 1);    // 1.25 → 1
  EXPECT_EQ(fx::shift_round(-5, 2, s), -1);
  EXPECT_EQ(fx::shift_round(3, -2, s), 12);
  EXPECT_EQ(fx::div_round(7, 2), 4);
  EXPECT_EQ(fx::div_round(-7, 2), -4);
  EXPECT_FALSE(s.hit);
}

TEST(FixedPoint, SaturatesInsteadOfWrappingAndSetsTheFlag) {
  fx::Saturation s;
  EXPECT_EQ(fx::add_sat(fx::kMax64, 1, s), fx::kMax64);
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::sub_sat(fx::kMin64, 1, s), fx::kMin64);
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::mul_q(std::int64_t{1} << 62, std::int64_t{1} << 62, 40, s), fx::kMax64);  // 2⁸⁴ in Q40
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::mul_q(-(std::int64_t{1} << 62), std::int64_t{1} << 62, 40, s), fx::kMin64);
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::shift_round(fx::Int128(1) << 120, -10, s), fx::Int128(1) << 126);
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::clamp128(fx::Int128(1) << 80, kS2Bound, s), kS2Bound);
  EXPECT_TRUE(s.hit);
  s = {};
  EXPECT_EQ(fx::add_sat(5, -7, s), -2);  // in range: exact, no flag
  EXPECT_FALSE(s.hit);
}

TEST(FixedPoint, ConstantsHoldTheConfiguredDoubleExactly) {
  for (double x : {9.65e-7, -7.05e-4, 9.8113, 2.5e-9, 4.1e-3 * 5e-5, -1.0, 1.0}) {
    EXPECT_EQ(fx::QConst::from(x).value(), x) << x;
    EXPECT_LT(std::abs(fx::QConst::from(x).mant), std::int64_t{1} << 62);
  }
  EXPECT_EQ(fx::QConst::from(0.0).mant, 0);
}

TEST(FixedPoint, IntegratorIsExactInIntegersAndSaturatesAtItsBound) {
  FixedIntegrator in(1e-4, {});
  const std::int64_t zero[3] = {0, 0, 0};
  in.start(zero);
  fx::Saturation s;
  const std::int64_t a[3] = {std::int64_t{1} << 40, -(std::int64_t{3} << 39), 7};  // 1, −1.5 m/s², 7 LSB
  for (int n = 0; n < 10000; ++n) in.step(a, 1, s);
  EXPECT_FALSE(s.hit);
  // A step from 0 to a: S1 = a(2n − 1), S2 = a + 2a n(n − 1), so x = a t²/2 − a t dt/2 + a dt²/4.
  const double t = 1.0, dt = 1e-4;
  EXPECT_NEAR(fx::to_double(in.x_q40_m(0, s), kOutQ), 0.5 * t * t - t * dt / 2.0 + dt * dt / 4.0, 1e-12);
  EXPECT_EQ(in.s1[2], 7 * (2 * 10000 - 1));  // integers: no rounding, no drift
  // Deliberate overflow: 2⁶² per sample leaves int64 within a few steps.
  const std::int64_t huge[3] = {std::int64_t{1} << 62, -(std::int64_t{1} << 62), 0};
  for (int n = 0; n < 8; ++n) in.step(huge, 1, s);
  EXPECT_TRUE(s.hit);
  EXPECT_EQ(in.s1[0], fx::kMax64);
  EXPECT_EQ(in.s1[1], fx::kMin64);
}

TEST(FixedPoint, StaticCompMatchesTheDoublePathToItsLsb) {
  SensorSpec spec;
  StaticCalibration cal;
  cal.cross_g_per_g(0, 1) = 2e-3, cal.cross_g_per_g(1, 0) = -1e-3;
  const StaticComp d(spec, Acquisition{}, Site{}, cal);
  FixedStaticComp q(d);
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int32_t> counts(-2500000, 2500000);
  std::uniform_real_distribution<float> temp(10.0F, 50.0F);
  fx::Saturation s;
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const std::int32_t c[3] = {counts(rng), counts(rng), counts(rng)};
    const float t = temp(rng);
    std::int64_t out[3];
    q.apply(c, temp_q24_c(t), out, s);
    const Eigen::Vector3d a = d.apply(c, static_cast<double>(t));
    for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(fx::to_double(out[i], fx::kAccelQ) - a[i]));
  }
  EXPECT_FALSE(s.hit);
  std::printf("fixed vs double static compensation over +-2.4 g, 10..50 C: worst %.2e m/s^2 (Q40 LSB %.2e)\n", worst,
              std::ldexp(1.0, -40));
  EXPECT_LT(worst, 64.0 * std::ldexp(1.0, -40));
}

TEST(FixedPoint, StaticCompSaturatesOnAbsurdCounts) {
  const StaticComp d(SensorSpec{}, Acquisition{}, Site{});
  FixedStaticComp q(d);
  fx::Saturation s;
  const std::int32_t c[3] = {std::numeric_limits<std::int32_t>::max(), 0, std::numeric_limits<std::int32_t>::min()};
  std::int64_t out[3];
  q.apply(c, temp_q24_c(20.0F), out, s);
  EXPECT_TRUE(s.hit);  // v² of 2072 g leaves Q44
}

}  // namespace
}  // namespace eical::dsp
