#include "sim/simulate.hpp"

#include "dsp/core/error.hpp"
#include "sim/daq/decimation_filter.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/machine/axis_motion.hpp"
#include "sim/machine/geometry.hpp"
#include "sim/machine/structural_modes.hpp"
#include "sim/machine/vibration.hpp"
#include "sim/nc/klipper_excitation.hpp"
#include "sim/psd/psd_strip.hpp"
#include "sim/reference/reference_encoder.hpp"
#include "sim/sensor/earth_rate.hpp"
#include "sim/sensor/sensing_element.hpp"
#include "sim/truth.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

namespace eical::sim {
namespace {

enum Stream : std::uint64_t { sensor_noise = 1, bias_walk = 20, broadband = 30, psd_noise = 40, daq_noise = 50 };

Eigen::Vector3d axis_mask(const std::vector<std::string>& axes) {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (const auto& a : axes)
    if (a.size() == 1 && a[0] >= 'x' && a[0] <= 'z') m[a[0] - 'x'] = 1.0;
  return m;
}

void check(const Scenario& sc) {
  const dsp::Acquisition& acq = sc.meta.acquisition;
  if (!(acq.fs_hz > 0.0)) throw dsp::InputError("simulate: fs_hz must be positive");
  if (sc.oversample < 1) throw dsp::InputError("simulate: oversample must be >= 1");
  if (!(sc.daq.group_delay_samples >= 0.0) || !(sc.daq.group_delay_samples + sc.daq.skew_head_samples >= 0.0))
    throw dsp::InputError("simulate: DAQ delay (with the head skew) must not be negative");
  if (acq.adc_bits < 2 || acq.adc_bits > 32) throw dsp::InputError("simulate: adc_bits must be 2..32");
  if (sc.meta.psd.size() > static_cast<std::size_t>(dsp::kMaxPsd))
    throw dsp::InputError("simulate: more than " + std::to_string(dsp::kMaxPsd) + " PSD strips");
  for (const auto& t : sc.truth)
    if (!(t.spec.f0_hz > 0.0) || !(t.spec.zeta > 0.0))
      throw dsp::InputError("simulate: sensor f0_hz and zeta must be positive");
  if (!sc.meta.sensor_present[0] && !sc.meta.sensor_present[1])
    throw dsp::InputError("simulate: at least one sensor must be present");
}

}  // namespace

std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t purpose) noexcept {
  // splitmix64 of (seed, purpose): well-separated streams for neighbouring seeds.
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + purpose * 0xBF58476D1CE4E5B9ull + 0x94D049BB133111EBull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::unique_ptr<nc::SetPoint> scenario_set_point(const Scenario& sc) {
  if (sc.sweep.on)
    return std::make_unique<nc::AccelProfileSetPoint>(nc::klipper_segments(sc.sweep.test), sc.sweep.direction,
                                                      sc.sweep.start_mm, sc.sweep.lead_in_s, sc.sweep.tail_s);
  const dsp::Program& p = sc.meta.program;
  return std::make_unique<nc::Trajectory>(
      nc::interpolate_gcode(p.gcode.empty() ? gcode::program_gcode(p) : p.gcode, sc.meta.id + ".ngc", sc.limits));
}

dsp::Run simulate(const Scenario& sc) { return simulate(sc, static_cast<std::vector<Eigen::Vector3d>*>(nullptr)); }

dsp::Run simulate(const Scenario& sc, std::vector<Eigen::Vector3d>* true_rel_mm, JitteredCapture* capture) {
  Scenario with_program = sc;
  auto& p = with_program.meta.program;
  if (!sc.sweep.on && p.gcode.empty()) p.gcode = gcode::program_gcode(p);
  const auto tr = scenario_set_point(with_program);
  return simulate(with_program, *tr, true_rel_mm, capture);
}

dsp::Run simulate(const Scenario& sc, const nc::SetPoint& tr, std::vector<Eigen::Vector3d>* true_rel_mm,
                  JitteredCapture* capture) {
  check(sc);
  if (capture &&
      capture->jitter_s.size() != static_cast<std::size_t>(std::ceil(tr.duration_s() * sc.meta.acquisition.fs_hz)) + 1)
    throw dsp::InputError("simulate: the jittered capture needs one sampling time per frame");
  const dsp::Acquisition& acq = sc.meta.acquisition;
  dsp::Run run;
  run.meta = sc.meta;
  run.meta.format = "eical-run/1";

  const double fs = acq.fs_hz;
  const int ov = sc.oversample;
  const double h = 1.0 / (fs * ov);
  const auto n_frames = static_cast<std::size_t>(std::ceil(tr.duration_s() * fs)) + 1;
  const std::size_t n_int = n_frames * static_cast<std::size_t>(ov);
  const double g = sc.meta.site.g_mps2;
  const std::size_t n_psd = sc.meta.psd.size();

  // Frames: set-point, temperatures, triggers.
  run.frames.resize(n_frames);
  for (std::size_t n = 0; n < n_frames; ++n) {
    auto& f = run.frames[n];
    const double t = static_cast<double>(n) / fs;
    f.sample_index = static_cast<std::int64_t>(n);
    const Eigen::Vector3d p = tr.at(t).pos_mm;
    for (int a = 0; a < 3; ++a) f.cmd_mm[a] = p[a];
    for (int s = 0; s < 2; ++s) f.temp_c[s] = static_cast<float>(sc.truth[s].temperature.at(t));
  }
  for (const auto& t : tr.triggers()) {
    const auto n = static_cast<std::size_t>(
        std::clamp<long long>(std::llround(t.t_s * fs), 0, static_cast<long long>(n_frames - 1)));
    run.frames[n].trigger = t.code;
  }
  const bool has_ref = sc.meta.reference.has_value();
  Eigen::Vector3d ref_mask = Eigen::Vector3d::Zero();
  if (has_ref) ref_mask = axis_mask(sc.meta.reference->axes);
  for (int a = 0; a < 3; ++a) run.channels.ref[a] = ref_mask[a] != 0.0;
  run.channels.psd_count = static_cast<int>(n_psd);
  if (true_rel_mm) true_rel_mm->assign(n_frames, Eigen::Vector3d::Zero());

  // Machine, vibration, Earth rate, PSD.
  const Eigen::Vector3d table_mask = axis_mask(sc.meta.machine.table_axes),
                        head_mask = axis_mask(sc.meta.machine.head_axes);
  const Eigen::Vector3d start = tr.at(0.0).pos_mm;
  std::array<AxisMotion, 3> axes = {AxisMotion(sc.machine, 0, h, start[0]), AxisMotion(sc.machine, 1, h, start[1]),
                                    AxisMotion(sc.machine, 2, h, start[2])};
  const bool geometric = has_geometric_errors(sc.machine);
  DriveModeResponse common_mode(sc.common_vibration.mode, h), diff_mode(sc.differential_vibration, h);
  StructuralModesResponse structure(sc.resonance.modes, h);
  CommonAcceleration common(sc.common_vibration, g, h, ov, stream_seed(sc.seed, broadband));
  const bool common_on = sc.common_vibration.on();
  const Eigen::Vector3d omega = sc.coriolis ? earth_rate_machine(sc.meta.site) : Eigen::Vector3d::Zero();
  std::vector<PsdStrip> strips;
  for (std::size_t k = 0; k < n_psd; ++k)
    strips.emplace_back(sc.meta.psd[k], k < sc.psd.size() ? sc.psd[k] : PsdTruth{}, h);
  Eigen::Matrix3d to_sensor[2];
  for (int s = 0; s < 2; ++s) to_sensor[s] = sc.truth[s].spec.to_machine.inverse();

  // Internal-grid channels: specific force per sensing element (g), PSD lock-in outputs (V).
  // An absent sensor (a single-sensor run) is neither stored nor simulated.
  const bool present[2] = {sc.meta.sensor_present[0], sc.meta.sensor_present[1]};
  std::array<std::array<std::vector<double>, 3>, 2> sensor_g;
  for (int s = 0; s < 2; ++s)
    if (present[s])
      for (auto& a : sensor_g[static_cast<std::size_t>(s)]) a.resize(n_int);
  std::vector<std::vector<double>> psd_v(2 * n_psd, std::vector<double>(n_int));

  // Deviations of table, head and the common base (relative-position sense, mm) over a
  // three-sample window for their second differences.
  struct Window {
    Eigen::Vector3d table, head, base;
  };
  Window w_prev{}, w_cur{}, w_next{};
  nc::MotionState ms_cur{};
  const double inv_h2_m = 1e-3 / (h * h);  // mm → m over h²
  auto deviations = [&](const nc::MotionState& ms, double t) {
    Window w{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      if (axes[static_cast<std::size_t>(i)].active())
        d[i] = axes[static_cast<std::size_t>(i)].step(ms.pos_mm[i], ms.vel_mm_s[i]);
      if (geometric) d += geometric_deviation_mm(sc.machine, i, ms.pos_mm);
      (head_mask[i] != 0.0 ? w.head : w.table) += d;
    }
    if (diff_mode.on()) w.head += diff_mode.step(ms.acc_mm_s2);
    if (structure.on()) (sc.resonance.part == 1 ? w.head : w.table) += structure.step(ms.acc_mm_s2);
    for (const Tone& tone : sc.differential_tones) {  // displacement whose acceleration is amp·sin(ωt + φ)
      const double w_rad = 2.0 * std::numbers::pi * tone.freq_hz;
      w.head -= tone.amp_mg * 1e-3 * g * 1e3 / (w_rad * w_rad) *
                std::sin(w_rad * t + tone.phase_deg * std::numbers::pi / 180.0);
    }
    if (common_mode.on()) w.base = common_mode.step(ms.acc_mm_s2);
    return w;
  };

  for (std::size_t k = 0; k <= n_int; ++k) {
    // Advance the window to sample k (k = n_int: one sample past the end, for the last
    // second difference).
    const nc::MotionState ms_next = tr.at(static_cast<double>(k) * h);
    w_next = deviations(ms_next, static_cast<double>(k) * h);
    if (k == 0) {
      w_prev = w_cur = w_next;
      ms_cur = ms_next;
      continue;
    }
    const std::size_t j = k - 1;  // the sample completed now
    const Eigen::Vector3d acc_cmd = ms_cur.acc_mm_s2 * 1e-3, vel_cmd = ms_cur.vel_mm_s * 1e-3;
    Eigen::Vector3d a_table =
        -table_mask.cwiseProduct(acc_cmd) - (w_next.table - 2.0 * w_cur.table + w_prev.table) * inv_h2_m;
    Eigen::Vector3d a_head =
        head_mask.cwiseProduct(acc_cmd) + (w_next.head - 2.0 * w_cur.head + w_prev.head) * inv_h2_m;
    if (common_on) {
      const Eigen::Vector3d c = common.step() + (w_next.base - 2.0 * w_cur.base + w_prev.base) * inv_h2_m;
      a_table += c, a_head += c;
    }
    if (sc.coriolis) {
      a_table += coriolis_mps2(omega, -table_mask.cwiseProduct(vel_cmd));
      a_head += coriolis_mps2(omega, head_mask.cwiseProduct(vel_cmd));
    }
    const Eigen::Vector3d up(0.0, 0.0, g);
    const Eigen::Vector3d f_table = to_sensor[0] * (a_table + up) / g, f_head = to_sensor[1] * (a_head + up) / g;
    for (int a = 0; a < 3; ++a) {
      if (present[0]) sensor_g[0][a][j] = f_table[a];
      if (present[1]) sensor_g[1][a][j] = f_head[a];
    }
    const Eigen::Vector3d p_rel = ms_cur.pos_mm + w_cur.table + w_cur.head;
    for (std::size_t s = 0; s < n_psd; ++s) strips[s].step(p_rel, psd_v[2 * s][j], psd_v[2 * s + 1][j]);
    if (j % static_cast<std::size_t>(ov) == 0) {
      const std::size_t n = j / static_cast<std::size_t>(ov);
      auto& f = run.frames[n];
      for (int a = 0; a < 3; ++a)
        f.ref_mm[a] = ref_mask[a] != 0.0 ? reference_reading_mm(sc.reference, a, p_rel[a])
                                         : std::numeric_limits<double>::quiet_NaN();
      if (true_rel_mm) (*true_rel_mm)[n] = p_rel;
    }
    w_prev = w_cur, w_cur = w_next, ms_cur = ms_next;
  }

  // Sensing elements, DAQ filter, slow terms, noise, ADC.
  const double full_scale = std::ldexp(1.0, acq.adc_bits - 1);
  const double e_noise_v = sc.daq.noise_nv_per_rthz * 1e-9 * std::sqrt(fs);
  std::mt19937_64 daq_rng(stream_seed(sc.seed, daq_noise));
  std::normal_distribution<double> unit(0.0, 1.0);
  auto to_counts = [&](double volts, double e_noise, int channel, std::uint32_t& flags) {
    double c = std::round((volts + e_noise) / acq.adc_lsb_volt) +
               static_cast<double>(acq.adc_offset_counts + sc.daq.offset_counts[channel]);
    if (c > full_scale - 1 || c < -full_scale) {
      c = std::clamp(c, -full_scale, full_scale - 1);
      flags |= dsp::frame_flag::accel_saturated;
    }
    return static_cast<std::int32_t>(std::llround(c));
  };
  std::vector<double> filtered(n_frames), filtered_jittered, positions;
  if (capture) {
    capture->counts.assign(n_frames, {});
    filtered_jittered.resize(n_frames);
    positions.resize(n_frames);
    for (std::size_t n = 0; n < n_frames; ++n) positions[n] = static_cast<double>(n) + capture->jitter_s[n] * fs;
  }
  for (int s = 0; s < 2; ++s) {
    if (!present[s]) continue;
    const SensorTruth& st = sc.truth[s];
    sense(sensor_g[static_cast<std::size_t>(s)], st, h);
    // A digital MEMS chip has no anti-alias filter: its samples are its low-pass output,
    // delayed (a design length of 0 makes the filter a pure delay).
    const double delay = sc.daq.group_delay_samples + (s == 1 ? sc.daq.skew_head_samples : 0.0);
    const DecimationFilter daq_filter =
        sc.daq.anti_alias_filter ? DecimationFilter(ov, delay) : DecimationFilter(ov, delay, 0.4863, 0.0);
    // Bias steps at the start of every move, alternating in sign (ch. 8.3.2).
    std::vector<std::size_t> move_starts;
    for (const auto& [from, to] : tr.move_spans_s())
      move_starts.push_back(static_cast<std::size_t>(std::llround(from * fs)));
    for (int a = 0; a < 3; ++a) {
      daq_filter.apply(sensor_g[static_cast<std::size_t>(s)][static_cast<std::size_t>(a)], filtered.data(), n_frames);
      if (capture)
        daq_filter.apply_at(sensor_g[static_cast<std::size_t>(s)][static_cast<std::size_t>(a)], positions.data(),
                            filtered_jittered.data(), n_frames);
      std::mt19937_64 noise_rng(stream_seed(sc.seed, sensor_noise + static_cast<std::uint64_t>(3 * s + a)));
      std::mt19937_64 walk_rng(stream_seed(sc.seed, bias_walk + static_cast<std::uint64_t>(3 * s + a)));
      const double sigma_g = sc.noise ? st.spec.noise_ug_per_rthz * 1e-6 * std::sqrt(fs) : 0.0;
      const double walk_g = st.bias_rw_ug_per_rts * 1e-6 / std::sqrt(fs);
      double walk = 0.0, step_bias = 0.0;
      std::size_t next_move = 0;
      int step_sign = 1;
      for (std::size_t n = 0; n < n_frames; ++n) {
        const double t = static_cast<double>(n) / fs;
        // The slow terms act on the analog signal, so they see the DAQ delay too.
        const double t_analog = t - sc.daq.group_delay_samples / fs;
        const double dT = st.temperature.at(std::max(0.0, t_analog)) - st.spec.temp_ref_c;
        if (st.bias_step_ug != 0.0)
          while (next_move < move_starts.size() && static_cast<double>(move_starts[next_move]) / fs <= t_analog) {
            step_bias += step_sign * st.bias_step_ug * 1e-6, step_sign = -step_sign, ++next_move;
          }
        if (walk_g > 0.0) walk += walk_g * unit(walk_rng);
        const double bias = st.spec.bias_g[a] + st.spec.tc_bias_ug_per_c * 1e-6 * dT + walk + step_bias +
                            st.bias_drift_ug_per_s * 1e-6 * std::max(0.0, t_analog);
        const double k1 = st.spec.k1_v_per_g[a] * (1.0 + st.spec.tc_k1_ppm_per_c * 1e-6 * dT);
        const double noise = sigma_g > 0.0 ? sigma_g * unit(noise_rng) : 0.0;
        auto& f = run.frames[n];
        const double e_noise = e_noise_v > 0.0 ? e_noise_v * unit(daq_rng) : 0.0;
        f.accel_counts[3 * s + a] = to_counts(k1 * (filtered[n] + bias + noise), e_noise, 3 * s + a, f.flags);
        // The capture's sample: the same slow terms, noise and ADC, a little earlier or later.
        if (capture) {
          std::uint32_t ignored = 0;
          capture->counts[n][static_cast<std::size_t>(3 * s + a)] =
              to_counts(k1 * (filtered_jittered[n] + bias + noise), e_noise, 3 * s + a, ignored);
        }
      }
    }
  }
  if (n_psd > 0) {
    const DecimationFilter daq_filter(ov, sc.daq.group_delay_samples);
    std::mt19937_64 rng(stream_seed(sc.seed, psd_noise));
    for (std::size_t c = 0; c < 2 * n_psd; ++c) {
      const PsdTruth pt = c / 2 < sc.psd.size() ? sc.psd[c / 2] : PsdTruth{};
      const double sigma_v = sc.noise ? pt.noise_v_per_rthz * std::sqrt(fs) : 0.0;
      daq_filter.apply(psd_v[c], filtered.data(), n_frames);
      for (std::size_t n = 0; n < n_frames; ++n) {
        const double v = filtered[n] + (sigma_v > 0.0 ? sigma_v * unit(rng) : 0.0);
        run.frames[n].psd_counts[c] = static_cast<std::int32_t>(std::llround(
                                          std::clamp(std::round(v / acq.adc_lsb_volt), -full_scale, full_scale - 1))) +
                                      static_cast<std::int32_t>(acq.adc_offset_counts);
      }
    }
  }
  run.truth_toml = truth_toml(sc, tr);
  return run;
}

}  // namespace eical::sim
