// Sensor, DAQ, PSD and reference models against their definitions.
#include "sim/daq/decimation_filter.hpp"
#include "sim/psd/psd_strip.hpp"
#include "sim/reference/reference_encoder.hpp"
#include "sim/sensor/sensing_element.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace eical::sim {
namespace {

TEST(DaqFilter, PassBandToPoint4863FsStopBandBeyondNyquistDelayFromLength) {
  const DecimationFilter f(10, 38.8);
  EXPECT_EQ(f.taps(), 777u);  // 2·388 + 1: the data sheet's delay at 10x oversampling
  EXPECT_NEAR(f.gain(0.0), 1.0, 1e-12);
  for (double fr : {0.01, 0.1, 0.3, 0.45, 0.4863}) EXPECT_NEAR(f.gain(fr), 1.0, 1e-3) << fr;
  for (double fr : {0.57, 0.7, 1.0, 2.0, 4.9}) EXPECT_LT(std::abs(f.gain(fr)), 1e-4) << fr;  // ≤ −80 dB
}

TEST(DaqFilter, DelaysASineByTheTrueDelayIncludingFractions) {
  for (double d : {38.8, 39.9, 40.25}) {
    const DecimationFilter f(10, d);
    const double freq = 50.0, fs = 10000.0;
    std::vector<double> in(200000);
    for (std::size_t k = 0; k < in.size(); ++k)
      in[k] = std::sin(2 * std::numbers::pi * freq * static_cast<double>(k) / (10 * fs));
    std::vector<double> out(20000);
    f.apply(in, out.data(), out.size());
    for (std::size_t n = 1000; n < 19000; n += 1234)
      EXPECT_NEAR(out[n], std::sin(2 * std::numbers::pi * freq * (static_cast<double>(n) - d) / fs), 2e-5)
          << d << " " << n;
  }
}

TEST(SensingElement, DampingGrowsWithAccelerationAmplitude) {
  // A 0.5 g step: with ζ = ζ0 (1 + k|a|) the overshoot is smaller than with constant ζ0.
  SensorTruth s;
  s.spec.zeta = 0.3;
  auto overshoot = [&](double zeta_per_g) {
    s.zeta_per_g = zeta_per_g;
    std::array<std::vector<double>, 3> a;
    for (auto& axis : a) axis.assign(20000, 0.0);
    for (std::size_t k = 1000; k < a[0].size(); ++k) a[0][k] = 0.5;
    s.spec.k2_g_per_g2.setZero(), s.spec.k3_g_per_g3.setZero();
    sense(a, s, 1e-5);
    return *std::max_element(a[0].begin(), a[0].end()) - 0.5;
  };
  const double o0 = overshoot(0.0), o1 = overshoot(1.0);
  EXPECT_NEAR(o0, 0.5 * std::exp(-std::numbers::pi * 0.3 / std::sqrt(1 - 0.09)), 1e-4);  // PT2 overshoot
  EXPECT_LT(o1, 0.8 * o0);
}

TEST(SensingElement, StaticModelWithCrossTerms) {
  SensorTruth s;
  s.k_cross_g_per_g(0, 1) = 2e-4;
  s.k_cross2_g_per_g2(0, 2) = 1e-4;
  std::array<std::vector<double>, 3> a{std::vector<double>(10, 0.3), std::vector<double>(10, -0.2),
                                       std::vector<double>(10, 1.0)};
  sense(a, s, 1e-5);
  const double x = 0.3;
  EXPECT_NEAR(a[0].back(),
              x + s.spec.k2_g_per_g2[0] * x * x + s.spec.k3_g_per_g3[0] * x * x * x + 2e-4 * -0.2 + 1e-4 * x * 1.0,
              1e-12);
}

TEST(PsdStrip, SharesTheLightByPositionAndIsDarkOffTheStrip) {
  dsp::PsdSpec spec;
  spec.measures = "x", spec.center_mm[0] = 0.0, spec.center_mm[1] = -10.0, spec.length_mm = 10.0, spec.width_mm = 0.5;
  spec.lockin_tau_s = 0.0;  // no lock-in filter: follow at once for this test
  PsdTruth truth;
  PsdStrip strip(spec, truth, 1e-5);
  double i1 = 0, i2 = 0;
  for (double u : {-3.0, -1.0, 0.0, 2.5}) {
    strip.step(Eigen::Vector3d(u, -10.0, 0.0), i1, i2);
    EXPECT_NEAR(i1 + i2, truth.full_scale_v, 1e-9);
    EXPECT_NEAR((i1 - i2) / (i1 + i2) * spec.length_mm / 2.0, u, 1e-9);  // electrode 1 at +u
  }
  strip.step(Eigen::Vector3d(0.0, -9.0, 0.0), i1, i2);  // 1 mm beside the 0.5 mm strip
  EXPECT_EQ(i1 + i2, 0.0);
  strip.step(Eigen::Vector3d(0.0, -10.25, 0.0), i1, i2);  // spot centred on the edge: half its light
  EXPECT_NEAR(i1 + i2, truth.full_scale_v / 2.0, 1e-6);
}

TEST(PsdStrip, LockInFollowsWithItsTimeConstant) {
  dsp::PsdSpec spec;
  spec.lockin_tau_s = 2e-5;
  PsdStrip strip(spec, PsdTruth{}, 1e-5);
  double i1 = 0, i2 = 0;
  // One step of 10 µs = τ/2 over which the light rises linearly from dark to full.
  strip.step(Eigen::Vector3d(0.0, 0.0, 0.0), i1, i2);
  EXPECT_NEAR(i1 + i2, 2.0 * (1.0 - 2.0 * (1.0 - std::exp(-0.5))), 1e-9);
  // A spot moving along the strip at 100 mm/s reads exactly τ late (an analogue lock-in).
  const double v = 100.0, h = 1e-5;
  double u = -2.0;
  for (int k = 0; k < 200; ++k) strip.step(Eigen::Vector3d(u += v * h, 0.0, 0.0), i1, i2);
  EXPECT_NEAR((i1 - i2) / (i1 + i2) * 5.0, u - v * 2e-5, 1e-9);
}

TEST(Reference, ReadsWithScaleInterpolationErrorAndOneNanometre) {
  ReferenceTruth r;
  r.scale_ppm[0] = 1.0;
  EXPECT_NEAR(reference_reading_mm(r, 0, 10.0), 10.00001, 1e-12);
  r.scale_ppm[0] = 0.0;
  r.interp_nm[0][0] = 8.0;
  EXPECT_NEAR(reference_reading_mm(r, 0, 0.001), 0.001 + 8e-6 * std::sin(2 * std::numbers::pi * 0.25),
              1e-12);                                                           // 1 µm = ¼ period
  EXPECT_DOUBLE_EQ(reference_reading_mm(ReferenceTruth{}, 0, 1.0000004), 1.0);  // 1 nm resolution
}

TEST(SimulateChain, TemperatureChannelAndSkewedHeadChannels) {
  Scenario sc = step_scenario(0.0, 50.0, 3250.0, 1);
  sc.noise = false;
  sc.truth[0].temperature = {21.0, 2.0, 5.0};
  sc.daq.skew_head_samples = 0.5;
  const dsp::Run run = simulate(sc);
  const double t_end = static_cast<double>(run.frames.size() - 1) / run.meta.acquisition.fs_hz;
  EXPECT_NEAR(run.frames.back().temp_c[0], 21.0 + 2.0 * (1.0 - std::exp(-t_end / 5.0)), 1e-4);
  EXPECT_NEAR(run.frames.front().temp_c[0], 21.0, 1e-6);
  // The table moves x: its x channel sees −a; put a head sensor on x too and compare timing
  // by the zero crossing of the jerk-limited acceleration ramps (0.5 sample apart).
  Scenario both = sc;
  both.meta.machine.head_axes = {"x", "z"};
  both.meta.machine.table_axes = {"x", "y"};  // x on both: the head's x = +p, the table's x = −p
  const dsp::Run r = simulate(both);
  auto first_above = [&](int ch, double sign) {
    const double rest = r.frames[0].accel_counts[ch];
    for (std::size_t n = 1; n < r.frames.size(); ++n) {
      const double a0 = sign * (r.frames[n - 1].accel_counts[ch] - rest),
                   a1 = sign * (r.frames[n].accel_counts[ch] - rest);
      if (a1 > 1e5 && a0 <= 1e5) return static_cast<double>(n - 1) + (1e5 - a0) / (a1 - a0);
    }
    return -1.0;
  };
  EXPECT_NEAR(first_above(3, 1.0) - first_above(0, -1.0), 0.5, 0.02);
}

}  // namespace
}  // namespace eical::sim
