// Realistic regimes of runs measured by other systems (sim/regimes): each regime's physics
// against what was put in — the mode's frequency and damping, the chip's noise density and
// quantisation step, aliasing above Nyquist, a mirrored mounting, one sensor, 51.2 kHz.
#include "sim/regimes/regimes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "sim/regimes/capture_clock.hpp"
#include "sim/regimes/klipper_like.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

namespace eical::sim {
namespace {

double decode_g(const dsp::Run& run, std::size_t n, int channel) {
  const auto& acq = run.meta.acquisition;
  const auto& s = run.meta.sensors[channel / 3];
  return static_cast<double>(run.frames[n].accel_counts[channel] - acq.adc_offset_counts) * acq.adc_lsb_volt /
         s.k1_v_per_g[channel % 3];
}

// A machine whose head moves every axis, with ideal sensors: no noise, a 32-bit ADC, no
// DAQ delay, f0 far above the signal, no k2/k3 and no bias.
Scenario ideal_head_scenario(const std::string& gcode) {
  Scenario sc = gcode_scenario(gcode, eical::dsp::ProgramKind::freeform, 3);
  sc.meta.machine.table_axes = {};
  sc.meta.machine.head_axes = {"x", "y", "z"};
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;
  sc.meta.acquisition.daq_group_delay_samples = 0.0;
  sc.daq.group_delay_samples = 0.0;
  for (int s = 0; s < 2; ++s) {
    auto& spec = sc.meta.sensors[s];
    spec.f0_hz = 20000.0, spec.k2_g_per_g2.setZero(), spec.k3_g_per_g3.setZero(), spec.bias_g.setZero();
    sc.truth[s].spec = spec;
    sc.truth[s].temperature.t0_c = spec.temp_ref_c;
  }
  return sc;
}

TEST(Regimes, ModeFrequencyAndDampingFromItsFreeDecay) {
  Scenario sc = ideal_head_scenario("G90 G21 G17\nG0 X0 Y0 Z0\nG4 P0.2\nM101\nG1 X10 F6000\nG4 P1.5\nM103\n");
  StructuralMode mode;
  mode.frequency_hz = 45.0, mode.damping_ratio = 0.02, mode.gain = 0.2, mode.direction = Eigen::Vector3d::UnitX();
  sc.resonance.modes = {mode};
  const dsp::Run run = simulate(sc);
  const auto sp = scenario_set_point(sc);
  const double fs = run.fs_hz(), g = sc.meta.site.g_mps2;
  const double t_end = sp->move_spans_s().back().second;
  // After the move the head rings: measured − commanded acceleration is the mode's m''.
  std::vector<double> t, r;
  for (std::size_t n = static_cast<std::size_t>((t_end + 0.02) * fs); n < run.frames.size() - 10; ++n) {
    t.push_back(static_cast<double>(n) / fs);
    r.push_back(decode_g(run, n, 3) - sp->at(t.back()).acc_mm_s2.x() / 1000.0 / g);
  }
  // Zero crossings give the damped period, the peaks between them the decay.
  std::vector<double> crossings, peak_t, peak_ln;
  double peak = 0.0, at = 0.0;
  for (std::size_t k = 1; k < r.size(); ++k) {
    if (std::abs(r[k]) > peak) peak = std::abs(r[k]), at = t[k];
    if ((r[k - 1] < 0.0) != (r[k] < 0.0)) {
      crossings.push_back(t[k - 1] + (t[k] - t[k - 1]) * r[k - 1] / (r[k - 1] - r[k]));
      if (crossings.size() > 1 && peak > 0.0) peak_t.push_back(at), peak_ln.push_back(std::log(peak));
      peak = 0.0;
    }
  }
  ASSERT_GT(crossings.size(), 40u);
  const double wd =
      std::numbers::pi * static_cast<double>(crossings.size() - 1) / (crossings.back() - crossings.front());
  double mt = 0, ml = 0;
  const auto n_peaks = static_cast<double>(peak_t.size());
  for (std::size_t k = 0; k < peak_t.size(); ++k) mt += peak_t[k] / n_peaks, ml += peak_ln[k] / n_peaks;
  double stt = 0, stl = 0;
  for (std::size_t k = 0; k < peak_t.size(); ++k)
    stt += (peak_t[k] - mt) * (peak_t[k] - mt), stl += (peak_t[k] - mt) * (peak_ln[k] - ml);
  const double sigma = -stl / stt, wn = std::hypot(wd, sigma);
  const double f_hz = wn / (2 * std::numbers::pi), zeta = sigma / wn;
  std::printf("mode put in: 45 Hz, zeta 0.02; free decay of the simulated head: %.3f Hz, zeta %.4f\n", f_hz, zeta);
  EXPECT_NEAR(f_hz, 45.0, 0.1);
  EXPECT_NEAR(zeta, 0.02, 0.001);
}

// H1 = S_xy / S_xx (Welch, Hann, 50 % overlap) of measured over commanded acceleration.
std::vector<std::complex<double>> frf(const std::vector<double>& x, const std::vector<double>& y, std::size_t seg) {
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> sxy(seg / 2 + 1), X, Y;
  std::vector<double> sxx(seg / 2 + 1, 0.0), bx(seg), by(seg);
  for (std::size_t s = 0; s + seg <= x.size(); s += seg / 2) {
    for (std::size_t k = 0; k < seg; ++k) {
      const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(seg));
      bx[k] = w * x[s + k], by[k] = w * y[s + k];
    }
    fft.fwd(X, bx), fft.fwd(Y, by);
    for (std::size_t k = 0; k <= seg / 2; ++k) sxy[k] += std::conj(X[k]) * Y[k], sxx[k] += std::norm(X[k]);
  }
  for (std::size_t k = 0; k <= seg / 2; ++k) sxy[k] /= sxx[k];
  return sxy;
}

TEST(Regimes, ModeShowsInTheSweptResponseOfAMemsHeadSensor) {
  nc::KlipperTest k = nc::KlipperTest::current();
  k.freq_start_hz = 20.0, k.freq_end_hz = 70.0, k.hz_per_sec = 1.0, k.sweeping_accel_mm_s2 = 0.0;
  Scenario sc = sweep_scenario(k, Eigen::Vector3d::UnitX(), 5);
  apply_mems(sc, mems_chip("adxl345"), 3200.0, Eigen::Vector3d(2e-3, -1e-3, 3e-3));
  set_sensors_present(sc, "head");
  StructuralMode mode;
  mode.frequency_hz = 42.0, mode.damping_ratio = 0.03, mode.gain = 0.15, mode.direction = Eigen::Vector3d::UnitX();
  sc.resonance.modes = {mode};
  const dsp::Run run = simulate(sc);
  const auto sp = scenario_set_point(sc);
  const double fs = run.fs_hz(), g = sc.meta.site.g_mps2;
  std::vector<double> cmd(run.frames.size()), meas(run.frames.size());
  for (std::size_t n = 0; n < run.frames.size(); ++n) {
    cmd[n] = sp->at(static_cast<double>(n) / fs).acc_mm_s2.x() / 1000.0 / g;
    meas[n] = decode_g(run, n, 3);
  }
  const std::size_t seg = 4 * static_cast<std::size_t>(fs);  // 0.25 Hz bins
  const auto h = frf(cmd, meas, seg);
  const double df = fs / static_cast<double>(seg);
  // The mode's own response, H = 1 + gain·ω²/(ωn² − ω² + 2iζωnω), fitted to 30–55 Hz
  // (gain by least squares for each fn, ζ of a grid).
  double best = kInf, f_fit = 0, zeta_fit = 0, gain_fit = 0;
  const auto b0 = static_cast<std::size_t>(30.0 / df), b1 = static_cast<std::size_t>(55.0 / df);
  for (double fn = 38.0; fn <= 46.0; fn += 0.02)
    for (double z = 0.01; z <= 0.06; z += 0.0005) {
      std::complex<double> num = 0.0;
      double den = 0.0;
      std::vector<std::complex<double>> shape(b1 - b0);
      for (std::size_t b = b0; b < b1; ++b) {
        const double w = 2 * std::numbers::pi * static_cast<double>(b) * df, wn = 2 * std::numbers::pi * fn;
        shape[b - b0] = w * w / std::complex<double>(wn * wn - w * w, 2 * z * wn * w);
        num += std::conj(shape[b - b0]) * (h[b] - 1.0), den += std::norm(shape[b - b0]);
      }
      const double gain = num.real() / den;
      double ss = 0.0;
      for (std::size_t b = b0; b < b1; ++b) ss += std::norm(h[b] - 1.0 - gain * shape[b - b0]);
      if (ss < best) best = ss, f_fit = fn, zeta_fit = z, gain_fit = gain;
    }
  std::printf(
      "mode put in: 42 Hz, zeta 0.03, gain 0.15; adxl345 at 3200 Hz, swept 20-70 Hz, measured/commanded fitted: %.2f "
      "Hz, zeta %.4f, gain %.3f\n",
      f_fit, zeta_fit, gain_fit);
  EXPECT_NEAR(f_fit, 42.0, 0.2);
  EXPECT_NEAR(zeta_fit, 0.03, 0.1 * 0.03);
  EXPECT_NEAR(gain_fit, 0.15, 0.1 * 0.15);
}

Scenario rest_scenario(double seconds) {
  char g[128];
  std::snprintf(g, sizeof g, "G90 G21\nG0 X0 Y0 Z0\nG4 P0.1\nM101\nG4 P%.3f\nM103\n", seconds);
  return gcode_scenario(g, eical::dsp::ProgramKind::freeform, 9);
}

TEST(Regimes, MemsChipHasItsNoiseDensityAndQuantisationStep) {
  Scenario sc = rest_scenario(4.0);
  const MemsChip& chip = mems_chip("mpu6050");
  const Eigen::Vector3d bias(2.5e-3, -1.5e-3, 4e-3);
  apply_mems(sc, chip, 0.0, bias);
  const dsp::Run run = simulate(sc);
  EXPECT_EQ(run.meta.acquisition.adc_bits, 16);
  EXPECT_DOUBLE_EQ(run.meta.acquisition.adc_lsb_volt, 32.0 / 65536.0);
  const double fs = run.fs_hz();
  for (int a = 0; a < 3; ++a) {
    double sum = 0, sum2 = 0;
    const auto n = static_cast<double>(run.frames.size());
    for (std::size_t k = 0; k < run.frames.size(); ++k) {
      const double v = decode_g(run, k, 3 + a);
      sum += v, sum2 += v * v;
    }
    const double mean = sum / n, density = std::sqrt(sum2 / n - mean * mean) / std::sqrt(fs);
    std::printf(
        "mpu6050 axis %d: noise put in %.1f ug/rtHz (two-sided), measured %.1f ug/rtHz; mean %.3f mg (bias %.3f "
        "mg%s)\n",
        a + 1, chip.noise_ug_per_rthz, density * 1e6, mean * 1e3, bias[a] * 1e3, a == 2 ? " + 1 g" : "");
    EXPECT_NEAR(density, chip.noise_ug_per_rthz * 1e-6, 0.05 * chip.noise_ug_per_rthz * 1e-6);
    EXPECT_NEAR(mean, bias[a] + (a == 2 ? 1.0 : 0.0), 4.0 * chip.noise_ug_per_rthz * 1e-6 * std::sqrt(fs / n));
  }
  // Without noise every reading is the quantised specific force: one LSB is 0.488 mg.
  sc.noise = false;
  const dsp::Run quiet = simulate(sc);
  for (int a = 0; a < 3; ++a) {
    const double f = bias[a] + (a == 2 ? 1.0 : 0.0);
    const auto expected = static_cast<std::int32_t>(std::llround(f / chip.lsb_g()));
    for (std::size_t k = 0; k < quiet.frames.size(); k += 97)
      ASSERT_EQ(quiet.frames[k].accel_counts[3 + a], expected) << a;
  }
}

// Amplitude of the component at f_hz over the record's last `seconds` (a whole number of
// periods; the start, where the DAQ filter sees the tone begin, left out).
double amplitude_at(const dsp::Run& run, int channel, double f_hz, double seconds) {
  std::complex<double> acc = 0.0;
  const double fs = run.fs_hz();
  const auto n0 = run.frames.size() - static_cast<std::size_t>(std::llround(seconds * fs));
  for (std::size_t n = n0; n < run.frames.size(); ++n)
    acc += decode_g(run, n, channel) *
           std::exp(std::complex<double>(0.0, -2 * std::numbers::pi * f_hz * static_cast<double>(n) / fs));
  return 2.0 * std::abs(acc) / static_cast<double>(run.frames.size() - n0);
}

TEST(Regimes, MemsChipAliasesWhatLiesAboveNyquistTheDaqFilterDoesNot) {
  // A 350 Hz tone of 10 mg on both parts; at 400 Hz it aliases to 50 Hz.
  auto with_tone = [](Scenario sc) {
    Tone t;
    t.freq_hz = 350.0, t.amp_mg = Eigen::Vector3d(10.0, 0.0, 0.0);
    sc.common_vibration.tones = {t};
    sc.noise = false;
    return sc;
  };
  Scenario mems = with_tone(rest_scenario(2.0));
  apply_mems(mems, mems_chip("mpu6050"), 400.0);  // its 260 Hz corner lies above the 200 Hz Nyquist
  const dsp::Run run = simulate(mems);
  const double r = 350.0 / 260.0, h350 = 1.0 / std::sqrt((1 - r * r) * (1 - r * r) + (2 * 0.707 * r) * (2 * 0.707 * r));
  const double alias = amplitude_at(run, 3, 50.0, 1.5);
  Scenario daq = with_tone(rest_scenario(2.0));
  set_daq_rate(daq, 400.0);
  daq.meta.acquisition.adc_bits = 32, daq.meta.acquisition.adc_lsb_volt = 1e-9;
  const double filtered = amplitude_at(simulate(daq), 3, 50.0, 1.5);
  std::printf(
      "350 Hz tone, 10 mg, sampled at 400 Hz: mpu6050 (corner 260 Hz, no anti-alias filter) shows %.3f mg at 50 Hz "
      "(expected 10 mg x |H(350 Hz)| = %.3f mg); "
      "the DAQ's anti-alias filter leaves %.2e mg\n",
      alias * 1e3, 10.0 * h350, filtered * 1e3);
  // The chip quantises at 0.49 mg: a 0.1 mg agreement is what its resolution allows.
  EXPECT_NEAR(alias, 10e-3 * h350, 0.1e-3);
  EXPECT_LT(filtered, 1e-6);
}

TEST(Regimes, WrongMountingShowsInTheDataAsPutIn) {
  nc::KlipperTest k = nc::KlipperTest::current();
  k.freq_start_hz = 20.0, k.freq_end_hz = 30.0, k.hz_per_sec = 2.0;
  for (const char* map : {"-x,y,z", "y,x,z", "-x,-y,z"}) {
    Scenario sc = sweep_scenario(k, Eigen::Vector3d::UnitX(), 2);
    Scenario ideal = ideal_head_scenario("G4 P1\n");
    sc.meta.sensors[0] = sc.meta.sensors[1] = ideal.meta.sensors[1];
    sc.truth[0] = sc.truth[1] = ideal.truth[1];
    sc.meta.acquisition = ideal.meta.acquisition;
    sc.daq = ideal.daq;
    sc.noise = false;
    set_sensors_present(sc, "head");
    apply_wrong_mounting(sc, 1, map);
    const dsp::Run run = simulate(sc);
    const auto sp = scenario_set_point(sc);
    const Eigen::Matrix3d m = sc.truth[1].spec.to_machine;
    // Regress each sensor axis on the commanded x acceleration (g).
    Eigen::Vector3d sxy = Eigen::Vector3d::Zero();
    double sxx = 0;
    for (std::size_t n = 0; n < run.frames.size(); ++n) {
      const double x = sp->at(static_cast<double>(n) / run.fs_hz()).acc_mm_s2.x() / 1000.0 / sc.meta.site.g_mps2;
      for (int a = 0; a < 3; ++a)
        sxy[a] += x * (decode_g(run, n, 3 + a) - (m.row(2)[a]));  // less gravity along that sensor axis
      sxx += x * x;
    }
    const Eigen::Vector3d slope = sxy / sxx;
    // The sensor axes see machine x through the true mounting: sensor = to_machineᵀ · machine.
    const Eigen::Vector3d expected = m.transpose() * Eigen::Vector3d::UnitX();
    std::printf("mounting %s: sensor axes respond to commanded x with [%.4f, %.4f, %.4f] (put in [%.0f, %.0f, %.0f])\n",
                map, slope.x(), slope.y(), slope.z(), expected.x(), expected.y(), expected.z());
    EXPECT_LT((slope - expected).norm(), 0.01) << map;
    EXPECT_NE(run.truth_toml->find(std::string("axes_map = \"") + map + "\""), std::string::npos);
  }
}

TEST(Regimes, OneSensorRunsLeaveTheOtherTriplexOut) {
  Scenario sc = rest_scenario(0.3);
  set_sensors_present(sc, "table");
  const dsp::Run run = simulate(sc);
  EXPECT_TRUE(run.meta.sensor_present[0]);
  EXPECT_FALSE(run.meta.sensor_present[1]);
  for (const auto& f : run.frames) ASSERT_EQ(f.accel_counts[3] | f.accel_counts[4] | f.accel_counts[5], 0);
  EXPECT_NE(run.truth_toml->find("sensors_present = \"table\""), std::string::npos);
  EXPECT_THROW(set_sensors_present(sc, "neither"), dsp::InputError);
}

TEST(Regimes, DaqAt51k2HzKeepsTheNoiseDensity) {
  Scenario sc = rest_scenario(0.4);
  set_daq_rate(sc, 51200.0);
  EXPECT_EQ(sc.oversample, 2);
  const dsp::Run run = simulate(sc);
  double sum = 0, sum2 = 0;
  const auto n = static_cast<double>(run.frames.size());
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    const double v = decode_g(run, k, 0);
    sum += v, sum2 += v * v;
  }
  const double density = std::sqrt(sum2 / n - (sum / n) * (sum / n)) / std::sqrt(run.fs_hz());
  std::printf("51.2 kHz DAQ: noise put in 0.40 ug/rtHz, measured %.3f ug/rtHz over %zu samples\n", density * 1e6,
              run.frames.size());
  EXPECT_NEAR(density, 0.4e-6, 0.02e-6);
}

TEST(Regimes, KlipperLikeRegimeDrawsWhatItPromises) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Scenario sc = klipper_like_scenario({"machine.resonance"}, seed);
    EXPECT_FALSE(sc.meta.sensor_present[0]);
    EXPECT_TRUE(sc.meta.sensor_present[1]);
    EXPECT_GE(sc.meta.acquisition.fs_hz, 400.0);
    EXPECT_LE(sc.meta.acquisition.fs_hz, 3200.0);
    EXPECT_FALSE(sc.daq.anti_alias_filter);
    EXPECT_TRUE(sc.sweep.on);
    EXPECT_FALSE(sc.meta.reference.has_value());
    ASSERT_EQ(sc.resonance.modes.size(), 2u);
    for (const auto& m : sc.resonance.modes) {
      EXPECT_GE(m.frequency_hz, 30.0);
      EXPECT_LE(m.frequency_hz, 100.0);
      EXPECT_GE(m.damping_ratio, 0.02);
      EXPECT_LE(m.damping_ratio, 0.1);
      EXPECT_GE(m.gain, 0.1);
      EXPECT_LE(m.gain, 0.8);
    }
    for (int a = 0; a < 3; ++a) EXPECT_GE(std::abs(sc.truth[1].spec.bias_g[a]), 1e-3);
    const Scenario mounted = klipper_like_scenario({"sensor.misalignment"}, seed);
    EXPECT_TRUE(mounted.resonance.modes.empty());
    EXPECT_FALSE(mounted.truth[1].axes_map.empty());
    EXPECT_EQ(klipper_like_scenario({"machine.resonance"}, seed).resonance.modes[0].frequency_hz,
              sc.resonance.modes[0].frequency_hz);
    const CaptureClock c = klipper_like_capture_clock(seed, sc.meta.acquisition.fs_hz);
    EXPECT_GE(c.jitter_rms_s * sc.meta.acquisition.fs_hz, 0.02);
    EXPECT_LE(c.jitter_rms_s * sc.meta.acquisition.fs_hz, 0.10);
  }
  // Close pairs the data resolve: in about one seed of three, and always apart by more than
  // the sum of their half-power half-widths.
  int close_pairs = 0;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const auto& m = klipper_like_scenario({"machine.resonance"}, seed).resonance.modes;
    ASSERT_EQ(m.size(), 2u);
    const double sep = std::abs(m[1].frequency_hz - m[0].frequency_hz);
    const double half_widths = m[0].damping_ratio * m[0].frequency_hz + m[1].damping_ratio * m[1].frequency_hz;
    EXPECT_GT(sep, half_widths) << "seed " << seed;
    close_pairs += sep < 3.0 * half_widths;
  }
  EXPECT_GE(close_pairs, 5);
  EXPECT_LE(close_pairs, 20);
  EXPECT_THROW(klipper_like_scenario({"machine.backlash"}, 1), dsp::InputError);
  // A short piece of it simulates: head only, the chip's resolution, the modes in truth.toml.
  Scenario sc = klipper_like_scenario({"machine.resonance"}, 2);
  sc.sweep.test.freq_end_hz = sc.sweep.test.freq_start_hz + 3.0;
  const dsp::Run run = simulate(sc);
  EXPECT_FALSE(run.meta.sensor_present[0]);
  EXPECT_EQ(run.frames.front().trigger, 101);
  EXPECT_EQ(run.frames.back().trigger, 103);
  EXPECT_NE(run.truth_toml->find("[[effects.\"machine.resonance\".modes]]"), std::string::npos);
  EXPECT_NE(run.truth_toml->find("anti_alias_filter = false"), std::string::npos);
}

TEST(Regimes, CaptureClockJittersAndLosesWhatItIsTold) {
  CaptureClock c;
  c.offset_s = 812.5, c.jitter_rms_s = 50e-6, c.batch = 16, c.lost_batches = 3, c.seed = 4;
  const CaptureSamples s = capture_samples(c, 100000, 1000.0);
  EXPECT_EQ(s.lost, 48u);
  EXPECT_TRUE(s.kept.front() && s.kept.back());
  EXPECT_EQ(s.jitter_s.front(), 0.0);
  EXPECT_NEAR(s.jitter_rms_s, 50e-6, 2e-6);
  EXPECT_DOUBLE_EQ(s.stamp_s(0, 1000.0, c), 812.5);
  for (std::size_t n = 1; n < s.jitter_s.size(); ++n) ASSERT_GT(s.stamp_s(n, 1000.0, c), s.stamp_s(n - 1, 1000.0, c));
}

}  // namespace
}  // namespace eical::sim
