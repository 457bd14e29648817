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
#include <cstdio>
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

// The run's two time grids: the frames at fs, the physics on an internal grid oversample
// times finer.
struct SimGrid {
  double fs_hz = 0.0;
  int oversample = 1;
  double h_s = 0.0;  // internal step
  std::size_t n_frames = 0, n_int = 0;
};

// Frames and internal samples grow with the program's duration: a program longer than the
// scenario's budget is refused before anything is allocated.
void check_budget(const Scenario& sc, const SimGrid& gr, double duration_s) {
  constexpr double kBudgetInternalHz = 100000.0;  // the budget's duration is at this internal rate
  const double frames = std::ceil(duration_s * gr.fs_hz) + 1.0;
  const double internal = frames * gr.oversample;
  const double max_internal = sc.max_duration_s * kBudgetInternalHz;
  if (std::isfinite(duration_s) && internal <= max_internal) return;
  const double channels =
      3.0 * (sc.meta.sensor_present[0] + sc.meta.sensor_present[1]) + 2.0 * static_cast<double>(sc.meta.psd.size());
  const double bytes_per_internal = 8.0 * channels, bytes_per_frame = static_cast<double>(sizeof(dsp::Frame));
  char b[400];
  std::snprintf(b, sizeof b,
                "simulate: the program runs %.1f s (%.3g frames at %.0f Hz, %.3g internal samples, about %.3g GB), "
                "beyond the longest simulation of %.0f s at 100 kHz (%.3g internal samples, about %.3g GB; "
                "--max-duration)",
                duration_s, frames, gr.fs_hz, internal,
                (frames * bytes_per_frame + internal * bytes_per_internal) / 1e9, sc.max_duration_s, max_internal,
                (max_internal / gr.oversample * bytes_per_frame + max_internal * bytes_per_internal) / 1e9);
  throw dsp::InputError(b);
}

SimGrid sim_grid(const Scenario& sc, const nc::SetPoint& tr) {
  SimGrid gr;
  gr.fs_hz = sc.meta.acquisition.fs_hz;
  gr.oversample = sc.oversample;
  check_budget(sc, gr, tr.duration_s());  // before any buffer is sized
  gr.h_s = 1.0 / (gr.fs_hz * gr.oversample);
  gr.n_frames = static_cast<std::size_t>(std::ceil(tr.duration_s() * gr.fs_hz)) + 1;
  gr.n_int = gr.n_frames * static_cast<std::size_t>(gr.oversample);
  return gr;
}

void check_capture(const JitteredCapture* capture, const SimGrid& gr) {
  if (capture && capture->jitter_s.size() != gr.n_frames)
    throw dsp::InputError("simulate: the jittered capture needs one sampling time per frame");
}

Eigen::Vector3d reference_mask(const Scenario& sc) {
  Eigen::Vector3d ref_mask = Eigen::Vector3d::Zero();
  if (sc.meta.reference.has_value()) ref_mask = axis_mask(sc.meta.reference->axes);
  return ref_mask;
}

// Frames: set-point, temperatures, triggers (on the nearest frame); the channels the run has.
void set_point_frames(const Scenario& sc, const nc::SetPoint& tr, const SimGrid& gr, dsp::Run& run) {
  const double fs = gr.fs_hz;
  const std::size_t n_frames = gr.n_frames;
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
  const Eigen::Vector3d ref_mask = reference_mask(sc);
  for (int a = 0; a < 3; ++a) run.channels.ref[a] = ref_mask[a] != 0.0;
  run.channels.psd_count = static_cast<int>(sc.meta.psd.size());
}

// Deviations of table, head and the common base (relative-position sense, mm) at one
// internal sample.
struct Deviations {
  Eigen::Vector3d table, head, base;
};

// Absolute accelerations of table and head (m/s²).
struct TableHead {
  Eigen::Vector3d table, head;
};

std::array<AxisMotion, 3> axis_motions(const Scenario& sc, const nc::SetPoint& tr, double h) {
  const Eigen::Vector3d start = tr.at(0.0).pos_mm;
  return {AxisMotion(sc.machine, 0, h, start[0]), AxisMotion(sc.machine, 1, h, start[1]),
          AxisMotion(sc.machine, 2, h, start[2])};
}

// The machine between the set-point and the sensors, one internal sample at a time: the
// axes' position loops and errors, the errors between axes, the head's modes against the
// table, the common vibration and the Earth rate.
class MachineMotion {
 public:
  MachineMotion(const Scenario& sc, const nc::SetPoint& tr, double h)
      : sc_(sc),
        g_(sc.meta.site.g_mps2),
        inv_h2_m_(1e-3 / (h * h)),  // mm → m over h²
        table_mask_(axis_mask(sc.meta.machine.table_axes)),
        head_mask_(axis_mask(sc.meta.machine.head_axes)),
        axes_(axis_motions(sc, tr, h)),
        geometric_(has_geometric_errors(sc.machine)),
        common_mode_(sc.common_vibration.mode, h),
        diff_mode_(sc.differential_vibration, h),
        structure_(sc.resonance.modes, h),
        common_(sc.common_vibration, g_, h, sc.oversample, stream_seed(sc.seed, broadband)),
        common_on_(sc.common_vibration.on()),
        omega_(sc.coriolis ? earth_rate_machine(sc.meta.site) : Eigen::Vector3d::Zero()) {}

  // The deviations at set-point ms, time t (advances the axes and modes by one sample).
  Deviations deviations(const nc::MotionState& ms, double t) {
    Deviations w{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      if (axes_[static_cast<std::size_t>(i)].active())
        d[i] = axes_[static_cast<std::size_t>(i)].step(ms.pos_mm[i], ms.vel_mm_s[i]);
      if (geometric_) d += geometric_deviation_mm(sc_.machine, i, ms.pos_mm);
      (head_mask_[i] != 0.0 ? w.head : w.table) += d;
    }
    if (diff_mode_.on()) w.head += diff_mode_.step(ms.acc_mm_s2);
    if (structure_.on()) (sc_.resonance.part == 1 ? w.head : w.table) += structure_.step(ms.acc_mm_s2);
    for (const Tone& tone : sc_.differential_tones) {  // displacement whose acceleration is amp·sin(ωt + φ)
      const double w_rad = 2.0 * std::numbers::pi * tone.freq_hz;
      w.head -= tone.amp_mg * 1e-3 * g_ * 1e3 / (w_rad * w_rad) *
                std::sin(w_rad * t + tone.phase_deg * std::numbers::pi / 180.0);
    }
    if (common_mode_.on()) w.base = common_mode_.step(ms.acc_mm_s2);
    return w;
  }

  // At the middle sample of a three-sample window (set-point ms there): the set-point's
  // acceleration plus the second difference of the deviations, common vibration, Coriolis.
  TableHead accelerations(const nc::MotionState& ms, const Deviations& prev, const Deviations& cur,
                          const Deviations& next) {
    const Eigen::Vector3d acc_cmd = ms.acc_mm_s2 * 1e-3, vel_cmd = ms.vel_mm_s * 1e-3;
    TableHead a{-table_mask_.cwiseProduct(acc_cmd) - (next.table - 2.0 * cur.table + prev.table) * inv_h2_m_,
                head_mask_.cwiseProduct(acc_cmd) + (next.head - 2.0 * cur.head + prev.head) * inv_h2_m_};
    if (common_on_) {
      const Eigen::Vector3d c = common_.step() + (next.base - 2.0 * cur.base + prev.base) * inv_h2_m_;
      a.table += c, a.head += c;
    }
    if (sc_.coriolis) {
      a.table += coriolis_mps2(omega_, -table_mask_.cwiseProduct(vel_cmd));
      a.head += coriolis_mps2(omega_, head_mask_.cwiseProduct(vel_cmd));
    }
    return a;
  }

 private:
  const Scenario& sc_;
  double g_, inv_h2_m_;
  Eigen::Vector3d table_mask_, head_mask_;
  std::array<AxisMotion, 3> axes_;
  bool geometric_;
  DriveModeResponse common_mode_, diff_mode_;
  StructuralModesResponse structure_;
  CommonAcceleration common_;
  bool common_on_;
  Eigen::Vector3d omega_;
};

// Internal-grid channels: specific force per sensing element (g), PSD lock-in outputs (V).
// An absent sensor (a single-sensor run) is neither stored nor simulated.
struct InternalChannels {
  bool present[2] = {false, false};
  std::array<std::array<std::vector<double>, 3>, 2> sensor_g;
  std::vector<std::vector<double>> psd_v;
};

InternalChannels internal_channels(const Scenario& sc, const SimGrid& gr) {
  InternalChannels ch;
  for (int s = 0; s < 2; ++s) ch.present[s] = sc.meta.sensor_present[s];
  for (int s = 0; s < 2; ++s)
    if (ch.present[s])
      for (auto& a : ch.sensor_g[static_cast<std::size_t>(s)]) a.resize(gr.n_int);
  ch.psd_v.assign(2 * sc.meta.psd.size(), std::vector<double>(gr.n_int));
  return ch;
}

// Specific force with gravity in each sensor's true mounting, in g.
class SpecificForce {
 public:
  explicit SpecificForce(const Scenario& sc) : g_(sc.meta.site.g_mps2) {
    for (int s = 0; s < 2; ++s) to_sensor_[s] = sc.truth[s].spec.to_machine.inverse();
  }

  void store(const TableHead& acc, std::size_t j, InternalChannels& ch) const {
    const Eigen::Vector3d up(0.0, 0.0, g_);
    const Eigen::Vector3d f_table = to_sensor_[0] * (acc.table + up) / g_,
                          f_head = to_sensor_[1] * (acc.head + up) / g_;
    for (int a = 0; a < 3; ++a) {
      if (ch.present[0]) ch.sensor_g[0][a][j] = f_table[a];
      if (ch.present[1]) ch.sensor_g[1][a][j] = f_head[a];
    }
  }

 private:
  double g_;
  Eigen::Matrix3d to_sensor_[2];
};

std::vector<PsdStrip> psd_strips(const Scenario& sc, double h) {
  std::vector<PsdStrip> strips;
  for (std::size_t k = 0; k < sc.meta.psd.size(); ++k)
    strips.emplace_back(sc.meta.psd[k], k < sc.psd.size() ? sc.psd[k] : PsdTruth{}, h);
  return strips;
}

// The reference reads the relative position at the frame's time, undelayed.
void read_reference(const Scenario& sc, const Eigen::Vector3d& ref_mask, const Eigen::Vector3d& p_rel, dsp::Frame& f) {
  for (int a = 0; a < 3; ++a)
    f.ref_mm[a] =
        ref_mask[a] != 0.0 ? reference_reading_mm(sc.reference, a, p_rel[a]) : std::numeric_limits<double>::quiet_NaN();
}

// The physics on the internal grid over a three-sample window of deviations (for their
// second differences): machine → accelerations → specific force per sensing element; the
// PSD strips and the reference see the relative position.
void simulate_motion(const Scenario& sc, const nc::SetPoint& tr, const SimGrid& gr, InternalChannels& ch, dsp::Run& run,
                     std::vector<Eigen::Vector3d>* true_rel_mm) {
  if (true_rel_mm) true_rel_mm->assign(gr.n_frames, Eigen::Vector3d::Zero());
  MachineMotion machine(sc, tr, gr.h_s);
  std::vector<PsdStrip> strips = psd_strips(sc, gr.h_s);
  const SpecificForce force(sc);
  const Eigen::Vector3d ref_mask = reference_mask(sc);
  const double h = gr.h_s;
  const auto ov = static_cast<std::size_t>(gr.oversample);
  Deviations w_prev{}, w_cur{}, w_next{};
  nc::MotionState ms_cur{};
  for (std::size_t k = 0; k <= gr.n_int; ++k) {
    // Advance the window to sample k (k = n_int: one sample past the end, for the last
    // second difference).
    const nc::MotionState ms_next = tr.at(static_cast<double>(k) * h);
    w_next = machine.deviations(ms_next, static_cast<double>(k) * h);
    if (k == 0) {
      w_prev = w_cur = w_next;
      ms_cur = ms_next;
      continue;
    }
    const std::size_t j = k - 1;  // the sample completed now
    force.store(machine.accelerations(ms_cur, w_prev, w_cur, w_next), j, ch);
    const Eigen::Vector3d p_rel = ms_cur.pos_mm + w_cur.table + w_cur.head;
    for (std::size_t s = 0; s < strips.size(); ++s) strips[s].step(p_rel, ch.psd_v[2 * s][j], ch.psd_v[2 * s + 1][j]);
    if (j % ov == 0) {
      const std::size_t n = j / ov;
      read_reference(sc, ref_mask, p_rel, run.frames[n]);
      if (true_rel_mm) (*true_rel_mm)[n] = p_rel;
    }
    w_prev = w_cur, w_cur = w_next, ms_cur = ms_next;
  }
}

// What the DAQ stage of every channel shares: the ADC, the electronics' noise and the
// buffers of the filtered signal. One normal distribution serves every random stream, as
// it always has: it keeps the second value of each pair it draws, so sharing it is part
// of which numbers a seed gives.
struct DaqStage {
  const Scenario& sc;
  SimGrid gr;
  double full_scale, e_noise_v;
  std::mt19937_64 daq_rng;
  std::normal_distribution<double> unit{0.0, 1.0};
  std::vector<double> filtered, filtered_jittered, positions;

  DaqStage(const Scenario& scenario, const SimGrid& grid, JitteredCapture* capture)
      : sc(scenario),
        gr(grid),
        full_scale(std::ldexp(1.0, sc.meta.acquisition.adc_bits - 1)),
        e_noise_v(sc.daq.noise_nv_per_rthz * 1e-9 * std::sqrt(gr.fs_hz)),
        daq_rng(stream_seed(sc.seed, daq_noise)),
        filtered(gr.n_frames) {
    if (!capture) return;
    capture->counts.assign(gr.n_frames, {});
    filtered_jittered.resize(gr.n_frames);
    positions.resize(gr.n_frames);
    for (std::size_t n = 0; n < gr.n_frames; ++n)
      positions[n] = static_cast<double>(n) + capture->jitter_s[n] * gr.fs_hz;
  }

  // Volts (and the electronics' noise) to counts with the channel's offset; clamped and
  // flagged at full scale.
  std::int32_t to_counts(double volts, double e_noise, int channel, std::uint32_t& flags) const {
    const dsp::Acquisition& acq = sc.meta.acquisition;
    double c = std::round((volts + e_noise) / acq.adc_lsb_volt) +
               static_cast<double>(acq.adc_offset_counts + sc.daq.offset_counts[channel]);
    if (c > full_scale - 1 || c < -full_scale) {
      c = std::clamp(c, -full_scale, full_scale - 1);
      flags |= dsp::frame_flag::accel_saturated;
    }
    return static_cast<std::int32_t>(std::llround(c));
  }
};

// Sensor s, axis a at the DAQ rate: the slow static terms (bias, its steps, drift and
// random walk, temperature of k1 and bias) on the filtered signal, white noise, the ADC.
void axis_counts(DaqStage& d, int s, int a, const std::vector<std::size_t>& move_starts, dsp::Run& run,
                 JitteredCapture* capture) {
  const Scenario& sc = d.sc;
  const SensorTruth& st = sc.truth[s];
  const double fs = d.gr.fs_hz;
  std::mt19937_64 noise_rng(stream_seed(sc.seed, sensor_noise + static_cast<std::uint64_t>(3 * s + a)));
  std::mt19937_64 walk_rng(stream_seed(sc.seed, bias_walk + static_cast<std::uint64_t>(3 * s + a)));
  const double sigma_g = sc.noise ? st.spec.noise_ug_per_rthz * 1e-6 * std::sqrt(fs) : 0.0;
  const double walk_g = st.bias_rw_ug_per_rts * 1e-6 / std::sqrt(fs);
  double walk = 0.0, step_bias = 0.0;
  std::size_t next_move = 0;
  int step_sign = 1;
  for (std::size_t n = 0; n < d.gr.n_frames; ++n) {
    const double t = static_cast<double>(n) / fs;
    // The slow terms act on the analog signal, so they see the DAQ delay too.
    const double t_analog = t - sc.daq.group_delay_samples / fs;
    const double dT = st.temperature.at(std::max(0.0, t_analog)) - st.spec.temp_ref_c;
    if (st.bias_step_ug != 0.0)
      while (next_move < move_starts.size() && static_cast<double>(move_starts[next_move]) / fs <= t_analog) {
        step_bias += step_sign * st.bias_step_ug * 1e-6, step_sign = -step_sign, ++next_move;
      }
    if (walk_g > 0.0) walk += walk_g * d.unit(walk_rng);
    const double bias = st.spec.bias_g[a] + st.spec.tc_bias_ug_per_c * 1e-6 * dT + walk + step_bias +
                        st.bias_drift_ug_per_s * 1e-6 * std::max(0.0, t_analog);
    const double k1 = st.spec.k1_v_per_g[a] * (1.0 + st.spec.tc_k1_ppm_per_c * 1e-6 * dT);
    const double noise = sigma_g > 0.0 ? sigma_g * d.unit(noise_rng) : 0.0;
    auto& f = run.frames[n];
    const double e_noise = d.e_noise_v > 0.0 ? d.e_noise_v * d.unit(d.daq_rng) : 0.0;
    f.accel_counts[3 * s + a] = d.to_counts(k1 * (d.filtered[n] + bias + noise), e_noise, 3 * s + a, f.flags);
    // The capture's sample: the same slow terms, noise and ADC, a little earlier or later.
    if (capture) {
      std::uint32_t ignored = 0;
      capture->counts[n][static_cast<std::size_t>(3 * s + a)] =
          d.to_counts(k1 * (d.filtered_jittered[n] + bias + noise), e_noise, 3 * s + a, ignored);
    }
  }
}

// Sensor s: its sensing elements, the DAQ filter with the true group delay (the head's
// skewed), then each axis' slow terms, noise and ADC.
void sensor_counts(DaqStage& d, int s, const nc::SetPoint& tr, std::array<std::vector<double>, 3>& sensor_g,
                   dsp::Run& run, JitteredCapture* capture) {
  const Scenario& sc = d.sc;
  const int ov = d.gr.oversample;
  sense(sensor_g, sc.truth[s], d.gr.h_s);
  // A digital MEMS chip has no anti-alias filter: its samples are its low-pass output,
  // delayed (a design length of 0 makes the filter a pure delay).
  const double delay = sc.daq.group_delay_samples + (s == 1 ? sc.daq.skew_head_samples : 0.0);
  const DecimationFilter daq_filter =
      sc.daq.anti_alias_filter ? DecimationFilter(ov, delay) : DecimationFilter(ov, delay, 0.4863, 0.0);
  // Bias steps at the start of every move, alternating in sign (ch. 8.3.2).
  std::vector<std::size_t> move_starts;
  for (const auto& [from, to] : tr.move_spans_s())
    move_starts.push_back(static_cast<std::size_t>(std::llround(from * d.gr.fs_hz)));
  for (int a = 0; a < 3; ++a) {
    daq_filter.apply(sensor_g[static_cast<std::size_t>(a)], d.filtered.data(), d.gr.n_frames);
    if (capture)
      daq_filter.apply_at(sensor_g[static_cast<std::size_t>(a)], d.positions.data(), d.filtered_jittered.data(),
                          d.gr.n_frames);
    axis_counts(d, s, a, move_starts, run, capture);
  }
}

// The PSD lock-in outputs through the same DAQ filter (nominal delay), with their noise.
void psd_counts(DaqStage& d, const std::vector<std::vector<double>>& psd_v, dsp::Run& run) {
  const Scenario& sc = d.sc;
  const dsp::Acquisition& acq = sc.meta.acquisition;
  const double fs = d.gr.fs_hz;
  const DecimationFilter daq_filter(d.gr.oversample, sc.daq.group_delay_samples);
  std::mt19937_64 rng(stream_seed(sc.seed, psd_noise));
  for (std::size_t c = 0; c < psd_v.size(); ++c) {
    const PsdTruth pt = c / 2 < sc.psd.size() ? sc.psd[c / 2] : PsdTruth{};
    const double sigma_v = sc.noise ? pt.noise_v_per_rthz * std::sqrt(fs) : 0.0;
    daq_filter.apply(psd_v[c], d.filtered.data(), d.gr.n_frames);
    for (std::size_t n = 0; n < d.gr.n_frames; ++n) {
      const double v = d.filtered[n] + (sigma_v > 0.0 ? sigma_v * d.unit(rng) : 0.0);
      run.frames[n].psd_counts[c] = static_cast<std::int32_t>(std::llround(std::clamp(
                                        std::round(v / acq.adc_lsb_volt), -d.full_scale, d.full_scale - 1))) +
                                    static_cast<std::int32_t>(acq.adc_offset_counts);
    }
  }
}

}  // namespace

void check_budget(const Scenario& scenario, const nc::SetPoint& set_point) {
  check(scenario);
  (void)sim_grid(scenario, set_point);
}

std::unique_ptr<nc::SetPoint> scenario_set_point(const Scenario& scenario) {
  if (scenario.sweep.on)
    return std::make_unique<nc::AccelProfileSetPoint>(nc::klipper_segments(scenario.sweep.test),
                                                      scenario.sweep.direction, scenario.sweep.start_mm,
                                                      scenario.sweep.lead_in_s, scenario.sweep.tail_s);
  // eical's own text: generated, or a user's file made canonical where it was read (whose
  // errors named that file); so no file name here, and never the run id.
  const dsp::Program& p = scenario.meta.program;
  return std::make_unique<nc::Trajectory>(
      nc::interpolate_gcode(p.gcode.empty() ? gcode::program_gcode(p) : p.gcode, "[program] gcode", scenario.limits));
}

dsp::Run simulate(const Scenario& scenario) {
  return simulate(scenario, static_cast<std::vector<Eigen::Vector3d>*>(nullptr));
}

dsp::Run simulate(const Scenario& scenario, std::vector<Eigen::Vector3d>* true_rel_mm, JitteredCapture* capture) {
  Scenario with_program = scenario;
  auto& p = with_program.meta.program;
  if (!scenario.sweep.on && p.gcode.empty()) p.gcode = gcode::program_gcode(p);
  const auto tr = scenario_set_point(with_program);
  return simulate(with_program, *tr, true_rel_mm, capture);
}

dsp::Run simulate(const Scenario& scenario, const nc::SetPoint& set_point, std::vector<Eigen::Vector3d>* true_rel_mm,
                  JitteredCapture* capture) {
  check(scenario);
  const SimGrid gr = sim_grid(scenario, set_point);
  check_capture(capture, gr);
  dsp::Run run;
  run.meta = scenario.meta;
  run.meta.format = "eical-run/1";
  set_point_frames(scenario, set_point, gr, run);
  // Machine, vibration, Earth rate, PSD on the internal grid.
  InternalChannels ch = internal_channels(scenario, gr);
  simulate_motion(scenario, set_point, gr, ch, run, true_rel_mm);
  // Sensing elements, DAQ filter, slow terms, noise, ADC.
  DaqStage daq(scenario, gr, capture);
  for (int s = 0; s < 2; ++s)
    if (ch.present[s]) sensor_counts(daq, s, set_point, ch.sensor_g[static_cast<std::size_t>(s)], run, capture);
  if (!ch.psd_v.empty()) psd_counts(daq, ch.psd_v, run);
  run.truth_toml = truth_toml(scenario, set_point);
  return run;
}

}  // namespace eical::sim
