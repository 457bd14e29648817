#include "tools/validate/thesis_checks.hpp"

#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace eical::tools {
// The simulator's scenarios and physics are what every check is made of.
using namespace eical::sim;

namespace {

constexpr double kUg = 1e-6;

// Near-ideal ADC and no white noise: what is left is the deterministic physics.
Scenario deterministic(Scenario sc) {
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;
  return sc;
}

// Peak |measured − true| relative position (µm) on `axes` while the set-point moves,
// pipeline without dynamic compensation (Bild 7-14, 7-5, 8-18 "uncompensated").
double peak_dynamic_error_um(const Scenario& sc, std::initializer_list<int> axes, dsp::DynamicComp comp) {
  const dsp::Run run = simulate(sc);
  dsp::AnalysisOptions options;
  options.dynamic = comp;
  const dsp::Analysis a = dsp::analyze_run(run, options);
  const dsp::Measurement& m = a.measurement;
  double peak = 0.0;
  for (std::size_t i = 0; i < m.pos_mm.size(); ++i) {
    if (m.sample_index[i] > m.motion_end_index) break;
    double e2 = 0.0;
    for (int ax : axes) e2 += std::pow(m.pos_mm[i][ax] - m.ref_mm[i][ax], 2);
    peak = std::max(peak, std::sqrt(e2) * 1e3);
  }
  return peak;
}

// A machine at rest for `duration_s` (G4 only), no reference.
Scenario rest_scenario(double duration_s, std::uint64_t seed) {
  Scenario sc =
      gcode_scenario("G90 G21 G17\nG4 P" + std::to_string(duration_s) + "\n", dsp::ProgramKind::freeform, seed);
  sc.meta.reference.reset();
  sc.oversample = 1;  // at rest the DAQ filter sees constants; the noise is added at fs
  return sc;
}

// Sensor x and y readings in g minus the true bias: what a perfect bias estimate leaves.
std::vector<double> channel_g(const dsp::Run& run, const Scenario& sc, int channel) {
  const int s = channel / 3, ax = channel % 3;
  const auto& acq = run.meta.acquisition;
  const dsp::SensorSpec& t = sc.truth[s].spec;
  const double dT = sc.truth[s].temperature.t0_c - t.temp_ref_c;
  const double k1 = t.k1_v_per_g[ax] * (1.0 + t.tc_k1_ppm_per_c * 1e-6 * dT);
  const double bias = t.bias_g[ax] + t.tc_bias_ug_per_c * 1e-6 * dT;
  std::vector<double> g(run.frames.size());
  for (std::size_t n = 0; n < g.size(); ++n)
    g[n] =
        static_cast<double>(run.frames[n].accel_counts[channel] - acq.adc_offset_counts) * acq.adc_lsb_volt / k1 - bias;
  return g;
}

// Trapezoid double integral (m) of a (g) over a window starting at rest.
double double_integral_m(const std::vector<double>& a_g, std::size_t from, std::size_t n, double fs, double g) {
  const double dt = 1.0 / fs;
  double v = 0.0, x = 0.0;
  for (std::size_t k = from + 1; k < from + n; ++k) {
    const double v_new = v + 0.5 * (a_g[k - 1] + a_g[k]) * g * dt;
    x += 0.5 * (v + v_new) * dt;
    v = v_new;
  }
  return x;
}

// σ over non-overlapping windows of the double integral of `signals` (µm).
double windowed_sigma_um(const std::vector<std::vector<double>>& signals, double window_s, double fs, double g) {
  const auto n = static_cast<std::size_t>(window_s * fs);
  double ss = 0.0;
  std::size_t count = 0;
  for (const auto& s : signals)
    for (std::size_t from = 0; from + n <= s.size(); from += n) {
      const double x = double_integral_m(s, from, n, fs, g);
      ss += x * x;
      ++count;
    }
  return std::sqrt(ss / static_cast<double>(count)) * 1e6;  // zero-mean process: rms = σ
}

ThesisCheck dynamic_circle() {
  ThesisCheck c{"uncompensated dynamic error, R10 circle 2.5 m/min", "Bild 7-14", "um", 150.0, 0.0, 0.75, 1.25, ""};
  c.simulated = peak_dynamic_error_um(deterministic(circle_scenario(10.0, 2500.0, 2)), {0, 1}, dsp::DynamicComp::none);
  c.how =
      "peak |p_meas - p_true| in XY during the motion; data-sheet PT2 (1 kHz, 0.707) + 38.8-sample DAQ filter, "
      "pipeline without dynamic compensation";
  return c;
}

ThesisCheck dynamic_step() {
  ThesisCheck c{"uncompensated dynamic error, 1-D move 3.25 m/min", "Bild 7-5, 8-18", "um", 210.0, 0.0, 0.75, 1.25, ""};
  c.simulated = peak_dynamic_error_um(deterministic(step_scenario(0.0, 50.0, 3250.0, 1)), {0}, dsp::DynamicComp::none);
  c.how = "peak |x_meas - x_true| during a 50 mm move, same chain";
  return c;
}

ThesisCheck white_noise(const ValidationOptions& o) {
  const double n_ug = 0.44, T = 1.2;
  ThesisCheck c{"double-integrated white noise 0.44 ug/rtHz over 1.2 s",
                "(6-25)..(6-28): n T^1.5 / sqrt(3)",
                "um",
                0.0,
                0.0,
                0.9,
                1.1,
                ""};
  Scenario sc = rest_scenario(T * o.monte_carlo_windows / 4.0 + 0.1, o.seed);
  for (auto& t : sc.truth) t.spec.noise_ug_per_rthz = n_ug;
  const dsp::Run run = simulate(sc);
  const double fs = run.meta.acquisition.fs_hz, g = run.meta.site.g_mps2;
  // Four channels without gravity (x, y of both sensors): independent noise streams.
  std::vector<std::vector<double>> ch;
  for (int channel : {0, 1, 3, 4}) ch.push_back(channel_g(run, sc, channel));
  c.thesis = n_ug * kUg * g * std::pow(T, 1.5) / std::sqrt(3.0) * 1e6;
  c.simulated = windowed_sigma_um(ch, T, fs, g);
  c.how = "Monte Carlo over " + std::to_string(o.monte_carlo_windows) +
          " windows of the simulated sensor output (true bias removed), trapezoid double integral";
  return c;
}

ThesisCheck quantisation(const ValidationOptions& o) {
  const double T = 1.2;
  ThesisCheck c{
      "quantisation, 23 effective bits, over 1.2 s", "ch. 7.1: 0.56 ug rms -> 0.04 um", "um", 0.04, 0.0, 0.8, 1.25, ""};
  Scenario sc = rest_scenario(T * o.monte_carlo_windows / 4.0 + 0.1, o.seed + 1);
  Scenario ideal = sc;
  sc.meta.acquisition.adc_bits = 23;
  sc.meta.acquisition.adc_lsb_volt = 20.0 / std::ldexp(1.0, 23);
  ideal.meta.acquisition.adc_bits = 32;
  ideal.meta.acquisition.adc_lsb_volt = 1e-10;
  // Same seed, same noise: the difference of the two runs is the quantisation error.
  const dsp::Run q = simulate(sc), r = simulate(ideal);
  const double fs = q.meta.acquisition.fs_hz, g = q.meta.site.g_mps2;
  std::vector<std::vector<double>> diff;
  for (int channel : {0, 1, 3, 4}) {
    std::vector<double> a = channel_g(q, sc, channel);
    const std::vector<double> b = channel_g(r, ideal, channel);
    for (std::size_t n = 0; n < a.size(); ++n) a[n] -= b[n];
    diff.push_back(std::move(a));
  }
  c.simulated = windowed_sigma_um(diff, T, fs, g);
  c.how = "same noise through a 23-bit and an ideal ADC; the difference double-integrated over 1.2 s windows";
  return c;
}

ThesisCheck coriolis_acceleration(double& position_um) {
  // 10 m/min due north (+X at heading 0) at 50° latitude: a_c = 2 Ω v sin φ on Y.
  Scenario sc =
      gcode_scenario("G90 G21 G17 G61\nG0 X0 Y0\nG4 P0.5\nG1 X250 F10000\nG4 P0.5\n", dsp::ProgramKind::freeform, 1);
  sc.meta.site.latitude_deg = 50.0;
  sc.meta.site.heading_deg = 0.0;
  sc.meta.reference.reset();
  sc = deterministic(sc);
  Scenario off = sc;
  sc.coriolis = true;
  const dsp::Run on_run = simulate(sc), off_run = simulate(off);
  // The table carries X: its Y channel sees 2 ω × (−v); relative (head − table) = 2 ω × v.
  const std::vector<double> a_on = channel_g(on_run, sc, 1), a_off = channel_g(off_run, off, 1);
  const double fs = on_run.meta.acquisition.fs_hz, g = on_run.meta.site.g_mps2;
  const auto from = static_cast<std::size_t>(0.8 * fs), n = static_cast<std::size_t>(1.0 * fs);  // cruise phase
  std::vector<double> rel(a_on.size());
  for (std::size_t k = 0; k < rel.size(); ++k) rel[k] = -(a_on[k] - a_off[k]);
  double mean = 0.0;
  for (std::size_t k = from; k < from + n; ++k) mean += rel[k];
  mean /= static_cast<double>(n);
  position_um = double_integral_m(rel, from, n + 1, fs, g) * 1e6;
  ThesisCheck c{"Coriolis, 10 m/min north at 50 deg", "(3-5), (3-6)", "ug", 1.9, mean * 1e6, 0.95, 1.05, ""};
  c.how = "simulated table Y channel with minus without Earth rate, mean over 1 s at cruise";
  return c;
}

ThesisCheck common_vibration(double& relative_peak_um) {
  // A gantry whose head moves X (single-sensor case of ch. 8.3.1, HERMLE): the machine rocks
  // on its foundation (8.8 Hz, ζ 3.5 %) when the drive accelerates, plus drive and floor tones
  // and broadband vibration — all common to head and table.
  Scenario sc = step_scenario(0.0, 50.0, 3250.0, 1, 7);
  sc.meta.machine.table_axes = {"y"};
  sc.meta.machine.head_axes = {"x", "z"};
  sc.common_vibration.mode = DriveMode{8.8, 0.035, Eigen::Vector3d(0.015, 0.015, 0.005)};
  sc.common_vibration.tones.push_back({100.0, Eigen::Vector3d(4.0, 2.5, 1.0), 40.0});
  sc.common_vibration.tones.push_back({27.6, Eigen::Vector3d(0.35, 0.2, 0.1), 140.0});
  sc.common_vibration.broadband_rms_mg = Eigen::Vector3d(0.6, 1.4, 1.2);
  const dsp::Run run = simulate(sc);
  auto peak_x_error = [](const dsp::Run& r) {
    const dsp::Measurement m = dsp::analyze_run(r).measurement;
    double peak = 0.0;
    for (std::size_t i = 0; i < m.pos_mm.size(); ++i)
      peak = std::max(peak, std::abs(m.pos_mm[i].x() - m.ref_mm[i].x()) * 1e3);
    return peak;
  };
  relative_peak_um = peak_x_error(run);
  // One sensor only: the table sensor's channels held at their first value.
  dsp::Run head_only = run;
  for (auto& f : head_only.frames)
    for (int ch = 0; ch < 3; ++ch) f.accel_counts[ch] = run.frames[0].accel_counts[ch];
  ThesisCheck c{"single head sensor under common vibration",
                "ch. 8.3.1 (HERMLE: +-20 um)",
                "um",
                20.0,
                peak_x_error(head_only),
                0.5,
                2.0,
                ""};
  c.how =
      "peak |x_meas - x_true| of a 50 mm move, 8.8 Hz machine rocking + tones + broadband common to head and table, "
      "head sensor alone";
  return c;
}

}  // namespace

std::vector<ThesisCheck> validate_against_thesis(const ValidationOptions& options) {
  std::vector<ThesisCheck> rows;
  rows.push_back(dynamic_circle());
  rows.push_back(dynamic_step());
  rows.push_back(white_noise(options));
  rows.push_back(quantisation(options));
  double coriolis_um = 0.0;
  rows.push_back(coriolis_acceleration(coriolis_um));
  ThesisCheck cp{"Coriolis position error after 1 s",
                 "(3-6)",
                 "um",
                 9.3,
                 coriolis_um,
                 0.95,
                 1.05,
                 "double integral of the simulated Coriolis acceleration over 1 s of cruise"};
  rows.push_back(cp);
  double relative_um = 0.0;
  rows.push_back(common_vibration(relative_um));
  ThesisCheck rel{"relative measurement (head - table) under the same vibration",
                  "ch. 8.3.1 (KGM: +-1 um)",
                  "um",
                  1.0,
                  relative_um,
                  0.2,
                  3.0,
                  "the same run through eical's relative pipeline (two sensors): the common vibration cancels; what is "
                  "left is sensor noise"};
  rows.push_back(rel);
  return rows;
}

}  // namespace eical::tools
