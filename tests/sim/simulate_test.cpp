#include "sim/simulate.hpp"
#include "dsp/core/float_limits.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace eical::sim {
namespace {

// Decoded sensor reading in g (nominal decoding, v1 sensors: U/k1 − bias ignores k2/k3).
double decode_g(const dsp::Run& run, std::size_t n, int channel) {
  const auto& acq = run.meta.acquisition;
  const auto& s = run.meta.sensors[channel / 3];
  const double u = static_cast<double>(run.frames[n].accel_counts[channel] - acq.adc_offset_counts) * acq.adc_lsb_volt;
  return u / s.k1_v_per_g[channel % 3];
}

TEST(Simulate, AtRestSensorsReadBiasPlusGravityWithTheRightNoise) {
  Scenario sc = circle_scenario(10.0, 2500.0, 1);
  const dsp::Run run = simulate(sc);
  // 0.0–0.45 s: at rest (the move starts at 0.5 s; the DAQ delay is 3.9 ms).
  const std::size_t n_rest = 4500;
  for (int ch : {0, 2, 5}) {
    double sum = 0, sum2 = 0;
    for (std::size_t n = 0; n < n_rest; ++n) {
      const double v = decode_g(run, n, ch);
      sum += v, sum2 += v * v;
    }
    const double mean = sum / n_rest, sd = std::sqrt(sum2 / n_rest - mean * mean);
    const int ax = ch % 3;
    const auto& s = sc.truth[ch / 3].spec;
    const double a = ax == 2 ? 1.0 : 0.0;
    // (6-16): scale and bias at the case temperature (the head's case is 0.5 °C above 20 °C).
    const double dT = sc.truth[ch / 3].temperature.t0_c - s.temp_ref_c;
    const double k1_ratio = 1.0 + s.tc_k1_ppm_per_c * 1e-6 * dT;
    const double expected = k1_ratio * (a + s.bias_g[ax] + s.tc_bias_ug_per_c * 1e-6 * dT + s.k2_g_per_g2[ax] * a * a +
                                        s.k3_g_per_g3[ax] * a * a * a);
    EXPECT_NEAR(mean, expected, 3e-6) << "channel " << ch;
    // Two-sided density n: per-sample std = n·√fs = 40 µg (quantisation adds 0.28 µg rms).
    EXPECT_NEAR(sd, 0.4e-6 * std::sqrt(10000.0), 0.05 * 40e-6) << "channel " << ch;
  }
}

TEST(Simulate, DeterministicForASeedAndDifferentAcrossSeeds) {
  const dsp::Run a = simulate(circle_scenario(10, 2500, 1, "ccw", 7));
  const dsp::Run b = simulate(circle_scenario(10, 2500, 1, "ccw", 7));
  const dsp::Run c = simulate(circle_scenario(10, 2500, 1, "ccw", 8));
  ASSERT_EQ(a.frames.size(), b.frames.size());
  bool same = true, differ = false;
  for (std::size_t n = 0; n < a.frames.size(); ++n)
    for (int ch = 0; ch < 6; ++ch) {
      same &= a.frames[n].accel_counts[ch] == b.frames[n].accel_counts[ch];
      differ |= a.frames[n].accel_counts[ch] != c.frames[n].accel_counts[ch];
    }
  EXPECT_TRUE(same);
  EXPECT_TRUE(differ);
  EXPECT_EQ(*a.truth_toml, *b.truth_toml);
}

TEST(Simulate, DaqDelayShowsUpAsThatManySamples) {
  Scenario sc = circle_scenario(10.0, 2500.0, 1);
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;          // near-ideal ADC
  for (auto& t : sc.truth) t.spec.f0_hz = 20000.0;  // sensor dynamics far above the signal
  sc.daq.group_delay_samples = 38.8;
  const dsp::Run run = simulate(sc);
  // The table x channel reads −a_x(t − d/fs) (table moves against the relative motion).
  const nc::Trajectory tr = nc::interpolate_gcode(run.meta.program.gcode, "c", sc.limits);
  double best_d = 0, best_err = kInf;
  for (double d = 37.0; d <= 40.6; d += 0.05) {
    double err = 0;
    for (std::size_t n = 4000; n < run.frames.size(); n += 7) {
      const double a_true = -tr.at((static_cast<double>(n) - d) / 10000.0).acc_mm_s2.x() / 1000.0 / sc.meta.site.g_mps2;
      const auto& s = sc.truth[0].spec;
      const double a = decode_g(run, n, 0) - s.bias_g[0];
      const double a_lin = a - s.k2_g_per_g2[0] * a * a;  // undo the small nonlinearity to first order
      err += (a_lin - a_true) * (a_lin - a_true);
    }
    if (err < best_err) best_err = err, best_d = d;
  }
  // The PT2 adds its own low-frequency group delay 2ζ/ω0 (0.11 samples at 20 kHz).
  const double pt2_delay = 2 * 0.707 / (2 * 3.141592653589793 * 20000.0) * 10000.0;
  EXPECT_NEAR(best_d, 38.8 + pt2_delay, 0.03);
}

TEST(Simulate, TriggersAndSetPointFollowTheProgram) {
  const dsp::Run run = simulate(circle_scenario(10.0, 2500.0, 5));
  std::vector<std::int64_t> at;
  for (const auto& f : run.frames)
    if (f.trigger) at.push_back(f.sample_index);
  ASSERT_EQ(at.size(), 8u);
  EXPECT_EQ(at.front(), 4000);
  EXPECT_EQ(run.frames[at[1]].trigger, 102);
  EXPECT_NEAR(std::hypot(run.frames[30000].cmd_mm[0], run.frames[30000].cmd_mm[1]), 10.0, 1e-4);
  ASSERT_TRUE(run.truth_toml.has_value());
  for (const char* key : {"generator", "[effects]", "present", "[sensors.table]", "[sensors.head]", "[daq]", "[nc]",
                          "moves_s", "triggers"})
    EXPECT_NE(run.truth_toml->find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace eical::sim
