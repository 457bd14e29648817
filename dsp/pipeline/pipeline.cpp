#include "dsp/pipeline/pipeline.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/sensor_model_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace eical::dsp {
namespace {

constexpr std::uint32_t kAccelBad = frame_flag::accel_missing | frame_flag::accel_saturated | frame_flag::not_finite;

}  // namespace

PipelineConfig pipeline_config(const RunMeta& meta, std::size_t capacity_samples) {
  PipelineConfig c;
  c.acquisition = meta.acquisition;
  c.site = meta.site;
  c.sensors[0] = meta.sensors[0];
  c.sensors[1] = meta.sensors[1];
  c.sensor_present[0] = meta.sensor_present[0], c.sensor_present[1] = meta.sensor_present[1];
  c.psd = meta.psd;
  c.capacity_samples = capacity_samples;
  // Relative noise density, µg/√Hz · g → µm/s²/√Hz (two-sided, run-format.md).
  c.fusion.accel_noise_um_s2_rthz = std::hypot(meta.sensor_present[0] ? meta.sensors[0].noise_ug_per_rthz : 0.0,
                                               meta.sensor_present[1] ? meta.sensors[1].noise_ug_per_rthz : 0.0) *
                                    meta.site.g_mps2;
  c.strips_set_the_frame = meta.program.kind == ProgramKind::positioning;
  c.fusion.timing_uncertainty_s =
      dsp::timing_sigma_s(dsp::datasheet_covariance(meta.sensors, meta.acquisition.fs_hz), axis_owners(meta.machine));
  return c;
}

// The bit of each quality flag is its code's number.
static_assert(quality_flag::accel_missing == 1u << static_cast<unsigned>(FlagCode::accel_missing));
static_assert(quality_flag::not_finite == 1u << static_cast<unsigned>(FlagCode::not_finite));
static_assert(quality_flag::capacity_exceeded == 1u << static_cast<unsigned>(FlagCode::capacity_exceeded));
static_assert(quality_flag::psd_disagrees == 1u << static_cast<unsigned>(FlagCode::psd_disagrees));

std::vector<Flag> quality_flags(std::uint32_t bits) {
  std::vector<Flag> out;
  for (std::uint32_t b = 0; b <= static_cast<std::uint32_t>(FlagCode::psd_disagrees); ++b)
    if (bits & (1u << b)) out.push_back({static_cast<FlagCode>(b), {}, {}});
  return out;
}

Pipeline::Pipeline(const PipelineConfig& config)
    : config_(config),
      fixed_(config.arithmetic == Arithmetic::fixed_q),
      dt_s_(1.0 / config.acquisition.fs_hz),
      rest_noise_(config.acquisition.fs_hz, config.site.g_mps2) {
  if (fixed_ && config.coriolis)
    throw InputError("pipeline: the fixed-point path has no Coriolis term; use double arithmetic");
  if (fixed_ && (config.sensors[0].zeta_per_g != 0.0 || config.sensors[1].zeta_per_g != 0.0))
    throw InputError(
        "pipeline: the fixed-point path does not compensate damping that grows with the acceleration (zeta_per_g); use "
        "double arithmetic");
  if (fixed_ && config.dynamic != DynamicComp::none && config.dynamic != DynamicComp::position_level)
    throw InputError(
        std::string("pipeline: the fixed-point path compensates the dynamics at the position level only, not ") +
        dynamic_comp_name(config.dynamic));
  // The DAQ delay is not inverted by the series of dynamic_comp.hpp: a pure delay is exact
  // as a re-indexing of the trace (finish()), which also holds for the sharp transients of
  // backlash engagement and stick-slip, where the second-order series errs by c2·A (tens of
  // µm). The integrators compensate the sensor's PT2 only; the live estimate is predicted
  // over the delay.
  delay_samples_ = config.acquisition.daq_group_delay_samples;
  if (config.coriolis) coriolis_ = CoriolisComp(config.site);
  for (int s = 0; s < 2; ++s) {
    comp_[s] =
        StaticComp(config.sensors[s], config.acquisition, config.site, config.calibration[s], config.static_comp);
    fcomp_[s] = FixedStaticComp(comp_[s]);
    // A skew of the head's channels against the table's is a delay of that sensor's own:
    // the series inverts it with the PT2 (a fraction of a sample, no transient to mind).
    const double skew_s = s == 1 ? config.acquisition.daq_skew_head_samples * dt_s_ : 0.0;
    const DynamicCoefficients dyn = dynamic_coefficients(config.sensors[s], skew_s, config.dynamic);
    integ_[s] = SensorIntegrator(config.dynamic, dyn, dt_s_);
    integ_[s].c_amp_s3_per_m = config.sensors[s].zeta * config.sensors[s].zeta_per_g /
                               (2.0 * std::numbers::pi * config.sensors[s].f0_hz * config.site.g_mps2);
    finteg_[s] = FixedIntegrator(dt_s_, dyn);
    temp_c_[s] = static_cast<float>(config.sensors[s].temp_ref_c);
  }
  SupportConfig sc;
  sc.zupt = config.zupt, sc.nbs = config.nbs, sc.cupt = config.cupt, sc.smooth = config.smooth;
  sc.strips_set_the_frame = config.strips_set_the_frame;
  sc.record = config.trace == TraceKeeping::whole || config.trace == TraceKeeping::track;
  sc.compact = config.trace == TraceKeeping::track;
  sc.model = config.fusion;
  sc.standstill = config.standstill;
  sc.parallel = config.parallel;
  const double noise_mps2 = config.fusion.accel_noise_um_s2_rthz * 1e-6;
  supports_ = SupportStage(sc, config.acquisition, config.psd, noise_mps2 * noise_mps2 * config.acquisition.fs_hz,
                           config.capacity_samples, std::min(config.capacity_samples, config.reserve_samples));
  m_.fs_hz = config.acquisition.fs_hz;
  if (config.trace == TraceKeeping::whole) {
    for (auto* v : {&m_.pos_mm, &m_.vel_mm_s, &m_.cmd_mm, &m_.ref_mm}) v->reserve(config.capacity_samples);
    m_.sample_index.reserve(config.capacity_samples);
  } else if (config.keep_raw) {
    throw InputError("pipeline: keep_raw needs the whole trace (TraceKeeping::whole)");
  }
  if (config.keep_raw)
    for (auto* v : {&m_.raw.table_mps2, &m_.raw.head_mps2, &m_.raw.rest_rel_mps2}) v->reserve(config.capacity_samples);
  m_.triggers.reserve(trigger_capacity_);
  reset();
}

void Pipeline::reset() noexcept {
  phase_ = Phase::wait_start;
  quality_ = 0;
  saturation_ = {};
  saw_start_ = saw_end_ = false;
  prev_index_ = -1;
  prev_cmd_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bias_n_ = 0;
  for (int s = 0; s < 2; ++s) {
    a_[s] = last_valid_a_[s] = bias_sum_[s] = bias_[s] = Eigen::Vector3d::Zero();
    for (auto& h : rest_hist_[s]) h.setZero();
    for (int i = 0; i < 3; ++i) aq_[s][i] = last_valid_aq_[s][i] = fbias_[s][i] = 0, fbias_sum_[s][i] = 0;
  }
  start_index_ = motion_end_index_ = -1;
  rest_noise_.reset();
  still_since_ = -1;
  stored_ = 0;
  first_stored_ = -1;
  live_ = LiveEstimate{};
  m_.sample_index.clear();
  for (auto* v : {&m_.pos_mm, &m_.vel_mm_s, &m_.cmd_mm, &m_.ref_mm}) v->clear();
  m_.triggers.clear();
  m_.raw.table_mps2.clear(), m_.raw.head_mps2.clear(), m_.raw.rest_rel_mps2.clear();
  supports_.reset();
}

void Pipeline::store(const Frame& f, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s) noexcept {
  if (stored_ >= config_.capacity_samples) {
    quality_ |= quality_flag::capacity_exceeded;
    return;
  }
  if (stored_++ == 0) first_stored_ = f.sample_index;
  if (config_.trace != TraceKeeping::whole) {
    if (config_.sink) {
      TraceSample s;
      s.sample_index = f.sample_index;
      s.trigger = f.trigger;
      s.temp_c[0] = f.temp_c[0], s.temp_c[1] = f.temp_c[1];
      s.frame_flags = f.flags;
      s.pos_mm = pos_mm, s.vel_mm_s = vel_mm_s;
      s.cmd_mm = Eigen::Vector3d(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
      s.ref_mm = Eigen::Vector3d(f.ref_mm[0], f.ref_mm[1], f.ref_mm[2]);
      config_.sink->sample(s);
    }
    return;
  }
  m_.sample_index.push_back(f.sample_index);  // within the reserve: no allocation
  m_.pos_mm.push_back(pos_mm);
  m_.vel_mm_s.push_back(vel_mm_s);
  if (config_.keep_raw) {
    m_.raw.table_mps2.push_back(bias_free(0));
    m_.raw.head_mps2.push_back(bias_free(1));
  }
  m_.cmd_mm.emplace_back(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  m_.ref_mm.emplace_back(f.ref_mm[0], f.ref_mm[1], f.ref_mm[2]);
}

// Static compensation of both sensors into a_ (double) or aq_ (fixed); bad accelerations
// are replaced by the last valid ones, a missing temperature by the last valid one.
void Pipeline::compensate(const Frame& f) noexcept {
  for (int s = 0; s < 2; ++s)
    if (!(f.flags & frame_flag::temp_missing) && std::isfinite(f.temp_c[s])) temp_c_[s] = f.temp_c[s];
  for (int s = 0; s < 2; ++s) {
    if (!config_.sensor_present[s]) continue;  // absent: stays zero (reset)
    // A field of this sensor missing holds this sensor only; saturation and NaN hold both
    // (the frame's flag does not say which channel).
    const bool bad =
        (f.flags & (frame_flag::sensor_missing(s) | frame_flag::accel_saturated | frame_flag::not_finite)) != 0 ||
        ((f.flags & frame_flag::accel_missing) && !(f.flags & (frame_flag::table_missing | frame_flag::head_missing)));
    if (fixed_) {
      if (!bad) fcomp_[s].apply(&f.accel_counts[3 * s], temp_q24_c(temp_c_[s]), last_valid_aq_[s], saturation_);
      for (int i = 0; i < 3; ++i) aq_[s][i] = last_valid_aq_[s][i];
    } else {
      if (!bad) last_valid_a_[s] = comp_[s].apply(&f.accel_counts[3 * s], static_cast<double>(temp_c_[s]));
      a_[s] = last_valid_a_[s];
    }
  }
  if (saturation_.hit) quality_ |= quality_flag::fixed_saturated;
}

// First motion of the set-point: the sensors (delayed by d) still see the rest, so the
// rest mean is the bias; integration starts here.
void Pipeline::start_motion() noexcept {
  for (int s = 0; s < 2; ++s) {
    if (fixed_) {
      std::int64_t as[3];
      for (int i = 0; i < 3; ++i) {
        fbias_[s][i] = bias_n_ > 0
                           ? fx::sat64(fx::div_round(fbias_sum_[s][i], static_cast<fx::Int128>(bias_n_)), saturation_)
                           : aq_[s][i];
        as[i] = fx::sub_sat(aq_[s][i], fbias_[s][i], saturation_);
        bias_[s][i] = fx::to_double(fbias_[s][i], fx::kAccelQ);
      }
      finteg_[s].start(as);
    } else {
      bias_[s] = bias_n_ > 0 ? Eigen::Vector3d(bias_sum_[s] / static_cast<double>(bias_n_)) : a_[s];
      Eigen::Vector3d hist[3];
      for (int k = 0; k < 3; ++k)
        hist[k] =
            k < static_cast<int>(bias_n_) ? Eigen::Vector3d(rest_hist_[s][k] - bias_[s]) : Eigen::Vector3d::Zero();
      integ_[s].start(a_[s] - bias_[s], hist);
    }
  }
}

// This frame's acceleration of one sensor less its rest-window bias, m/s², machine axes.
Eigen::Vector3d Pipeline::bias_free(int sensor) const noexcept {
  if (!fixed_) return a_[sensor] - bias_[sensor];
  Eigen::Vector3d a;
  for (int i = 0; i < 3; ++i) a[i] = fx::to_double(aq_[sensor][i], fx::kAccelQ) - bias_[sensor][i];
  return a;
}

void Pipeline::integrate(std::int64_t k_samples, double dt_s, Eigen::Vector3d& pos_m,
                         Eigen::Vector3d& vel_mps) noexcept {
  if (fixed_) {
    std::int64_t x_q40[2][3], v_q40[2][3];
    for (int s = 0; s < 2; ++s) {
      std::int64_t as[3];
      for (int i = 0; i < 3; ++i) as[i] = fx::sub_sat(aq_[s][i], fbias_[s][i], saturation_);
      finteg_[s].step(as, k_samples, saturation_);
      for (int i = 0; i < 3; ++i)
        x_q40[s][i] = finteg_[s].x_q40_m(i, saturation_), v_q40[s][i] = finteg_[s].v_q40_mps(i, saturation_);
    }
    for (int i = 0; i < 3; ++i) {  // head − table (3-1)
      pos_m[i] = fx::to_double(fx::sub_sat(x_q40[1][i], x_q40[0][i], saturation_), kOutQ);
      vel_mps[i] = fx::to_double(fx::sub_sat(v_q40[1][i], v_q40[0][i], saturation_), kOutQ);
    }
    if (saturation_.hit) quality_ |= quality_flag::fixed_saturated;
    return;
  }
  for (int s = 0; s < 2; ++s) {
    Eigen::Vector3d as = a_[s] - bias_[s];
    if (config_.coriolis) as = coriolis_.apply(as, integ_[s].v_mps);  // (3-6), velocity fed back
    integ_[s].step(as, dt_s);
  }
  pos_m = integ_[1].x_out_m - integ_[0].x_out_m;  // head − table (3-1)
  vel_mps = integ_[1].v_out_mps - integ_[0].v_out_mps;
}

// A cycle of the pipeline (3-1): the frame's flags, the sensors' compensation, the PSD
// strips, then the phase of the program — the rest before it (bias, ZUPT window), its
// start, the motion integrated and fused with the supports.
void Pipeline::step(const Frame& frame) noexcept {
  note_quality(frame);
  compensate(frame);
  if (runs_supports()) supports_.psd_frame(frame);
  const FrameStep fs = advance(frame);
  switch (phase_) {
    case Phase::wait_start:
      if (frame.trigger != trigger::program_start) return;
      phase_ = Phase::rest;
      [[fallthrough]];
    case Phase::rest:
      if (!fs.cmd_moved) return rest_sample();
      return begin_motion(frame, fs);
    case Phase::moving: return moving_sample(frame, fs);
  }
}

void Pipeline::note_quality(const Frame& f) noexcept {
  if (f.flags & frame_flag::accel_missing) quality_ |= quality_flag::accel_missing;
  if (f.flags & frame_flag::accel_saturated) quality_ |= quality_flag::accel_saturated;
  if (f.flags & frame_flag::not_finite) quality_ |= quality_flag::not_finite;
  if (f.flags & frame_flag::gap_before) quality_ |= quality_flag::frames_lost;
}

Pipeline::FrameStep Pipeline::advance(const Frame& f) noexcept {
  FrameStep fs;
  fs.accel_valid = (f.flags & kAccelBad) == 0;
  fs.k_samples = prev_index_ >= 0 ? f.sample_index - prev_index_ : 1;
  fs.dt_s = static_cast<double>(fs.k_samples) * dt_s_;
  prev_index_ = f.sample_index;
  if (f.trigger != 0 && m_.triggers.size() < trigger_capacity_) m_.triggers.push_back({f.sample_index, f.trigger});
  if (f.trigger == trigger::program_start) saw_start_ = true;
  if (f.trigger == trigger::program_end) saw_end_ = true;
  fs.cmd_mm = Eigen::Vector3d(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  fs.cmd_valid = !(f.flags & frame_flag::cmd_missing) && fs.cmd_mm.allFinite();
  fs.cmd_moved = fs.cmd_valid && prev_cmd_.allFinite() && fs.cmd_mm != prev_cmd_;
  if (fs.cmd_valid) prev_cmd_ = fs.cmd_mm;
  live_.sample_index = f.sample_index;
  return fs;
}

// At rest before the motion: the sensors' bias sums and the ZUPT window.
void Pipeline::rest_sample() noexcept {
  for (int s = 0; s < 2; ++s) {
    if (fixed_) {
      for (int i = 0; i < 3; ++i) fbias_sum_[s][i] += aq_[s][i];
    } else {
      bias_sum_[s] += a_[s];
      rest_hist_[s][2] = rest_hist_[s][1], rest_hist_[s][1] = rest_hist_[s][0], rest_hist_[s][0] = a_[s];
    }
  }
  ++bias_n_;
  const Eigen::Vector3d rel = relative_acceleration();
  rest_noise_.sample(rel);
  if (runs_supports()) supports_.rest_sample(rel);
  if (config_.keep_raw && m_.raw.rest_rel_mps2.size() < config_.capacity_samples)
    m_.raw.rest_rel_mps2.push_back(rel);  // within the reserve
}

// The set-point moved: the bias is fixed, the integration starts at the commanded position.
void Pipeline::begin_motion(const Frame& f, const FrameStep& fs) noexcept {
  start_motion();
  rest_noise_.gap();
  still_since_ = f.sample_index;
  if (runs_supports()) supports_.start();
  // The programs dwell 0.1 s after M101; a trigger that reaches the DAQ clock a few
  // samples late must not flag a good rest.
  if (bias_n_ < static_cast<std::size_t>(0.05 / dt_s_)) quality_ |= quality_flag::short_rest_window;
  m_.rest_bias_rel_mps2 = bias_[1] - bias_[0];
  m_.rest_window_samples = bias_n_;
  start_pos_mm_ = prev_cmd_;
  start_index_ = motion_end_index_ = f.sample_index;
  phase_ = Phase::moving;
  live_.integrating = true;
  if (runs_supports() && stored_ < config_.capacity_samples)
    supports_.step({0, 1, fs.accel_valid, bias_free(0), bias_free(1), start_pos_mm_, Eigen::Vector3d::Zero(),
                    fs.cmd_valid, fs.cmd_moved, fs.cmd_mm});
  store(f, start_pos_mm_, Eigen::Vector3d::Zero());
}

// In motion: integrate, fuse with the supports, publish the live estimate, store.
Eigen::Vector3d Pipeline::relative_acceleration() const noexcept {
  return fixed_ ? Eigen::Vector3d(bias_free(1) - bias_free(0)) : Eigen::Vector3d(a_[1] - a_[0]);
}

void Pipeline::note_stillness(const Frame& f, const FrameStep& fs) noexcept {
  // A stop counts once the servo has settled and the DAQ's delay has passed: 0.25 s after
  // the set-point's last move (a settling lag of a few µm is hundreds of µg at first).
  constexpr double kSettleS = 0.25;
  if (fs.cmd_moved || still_since_ < 0) still_since_ = f.sample_index;
  const bool settled = static_cast<double>(f.sample_index - still_since_) * dt_s_ >= kSettleS;
  if (!settled || !fs.accel_valid || fs.k_samples != 1) return rest_noise_.gap();
  rest_noise_.sample(relative_acceleration());
}

void Pipeline::moving_sample(const Frame& f, const FrameStep& fs) noexcept {
  if (fs.cmd_moved) motion_end_index_ = f.sample_index;
  note_stillness(f, fs);
  Eigen::Vector3d pos_m, vel_mps;
  integrate(fs.k_samples, fs.dt_s, pos_m, vel_mps);
  const Eigen::Vector3d pos_mm = start_pos_mm_ + pos_m * 1000.0;
  const Eigen::Vector3d vel_mm_s = vel_mps * 1000.0;
  const std::size_t k = stored_;
  if (runs_supports() && k < config_.capacity_samples)
    supports_.step({k, fs.k_samples, fs.accel_valid, bias_free(0), bias_free(1), pos_mm, vel_mm_s, fs.cmd_valid,
                    fs.cmd_moved, fs.cmd_mm});
  // The live filter's estimate, predicted over the DAQ delay (what finish() re-indexes).
  const Eigen::Vector3d live_pos = pos_mm - supports_.live_dx_mm();
  live_.vel_mm_s = vel_mm_s - supports_.live_dv_mm_s();
  live_.pos_mm = config_.dynamic == DynamicComp::none
                     ? live_pos
                     : Eigen::Vector3d(live_pos + live_.vel_mm_s * (delay_samples_ * dt_s_));
  store(f, pos_mm, vel_mm_s);  // frames after M103 belong to the rest (ZUPT) window too
}

void Pipeline::align_delay(Measurement& m) const {
  // Sample k of the trace holds what the sensors saw at k − d (DAQ filter delay, 38.8
  // samples nominal): move it back by d so that it lines up with the set-point and the
  // reference, interpolating linearly between samples; the last d samples (at rest after
  // the motion) hold the final value.
  const std::size_t n = m.pos_mm.size();
  const double d = delay_samples_;
  if (!(d > 0.0) || n < 2) return;
  for (auto* trace : {&m.pos_mm, &m.vel_mm_s}) {
    auto& x = *trace;
    for (std::size_t k = 0; k < n; ++k) {
      const double src = static_cast<double>(k) + d;
      const auto i = static_cast<std::size_t>(src);
      if (i + 1 >= n) {
        x[k] = x[n - 1];
        continue;
      }
      const double f = src - static_cast<double>(i);
      x[k] = (1.0 - f) * x[i] + f * x[i + 1];  // i ≥ k: reads ahead of what it writes
    }
  }
}

void Pipeline::apply_supports(Measurement& m) {
  if (config_.keep_raw) {
    m.raw.pos_mm = m.pos_mm;
    m.raw.vel_mm_s = m.vel_mm_s;
    m.raw.rest_bias_mps2[0] = bias_[0];
    m.raw.rest_bias_mps2[1] = bias_[1];
  }
  std::vector<Eigen::Vector3d> sigma;
  m.supports = supports_.finish(m.sample_index, m.pos_mm, m.vel_mm_s, sigma);
  if (config_.keep_raw || config_.keep_schedule) m.raw.schedule = supports_.schedule();
  m.sigma_um = std::move(sigma);
  // The raw integrated velocity at the last standstill: what ZUPT takes out there.
  Eigen::Vector3d v_rest = Eigen::Vector3d::Zero();
  if (!m.supports.rest_windows.empty()) {
    const RestWindow& last = m.supports.rest_windows.back();
    const auto first = static_cast<std::size_t>(
        std::lower_bound(m.sample_index.begin(), m.sample_index.end(), last.first_index) - m.sample_index.begin());
    const auto end = static_cast<std::size_t>(
        std::upper_bound(m.sample_index.begin(), m.sample_index.end(), last.last_index) - m.sample_index.begin());
    if (end > first) {
      const auto [v, cnt] = supports_.recorded_velocity_sum(first, end - 1);
      if (cnt > 0) v_rest = v / static_cast<double>(cnt);
    }
  }
  rest_windows_done(m, v_rest);
}

void Pipeline::rest_windows_done(Measurement& m, const Eigen::Vector3d& last_rest_velocity_mm_s) {
  if (m.supports.diverged) quality_ |= quality_flag::supports_diverged;
  if (m.supports.psd_disagrees) quality_ |= quality_flag::psd_disagrees;
  const std::int64_t motion_end_sensor = motion_end_index_ + static_cast<std::int64_t>(std::ceil(delay_samples_));
  bool rest_after = false;
  for (const RestWindow& w : m.supports.rest_windows) {
    m.zupt_window_samples += w.samples;
    rest_after |= w.last_index > motion_end_sensor;
  }
  if (!m.supports.rest_windows.empty()) m.zupt_velocity_error_mm_s = last_rest_velocity_mm_s;
  if (config_.zupt && !rest_after) quality_ |= quality_flag::no_zupt_window;
}

Measurement Pipeline::finish() {
  Measurement m = std::move(m_);
  m_ = Measurement{};
  if (!saw_start_) quality_ |= quality_flag::no_start_trigger;
  if (!saw_end_) quality_ |= quality_flag::no_end_trigger;
  m.start_index = start_index_;
  m.motion_end_index = motion_end_index_;
  if (phase_ != Phase::moving) quality_ |= quality_flag::no_motion;
  m.rest_noise = rest_noise_.result();

  // Supports in the sensors' time base (the PSD channels are delayed like the sensors),
  // then onto the set-point's time. DynamicComp::none leaves the DAQ delay in as well
  // (the thesis' "uncompensated").
  if (phase_ == Phase::moving && !m.sample_index.empty()) apply_supports(m);
  if (config_.dynamic != DynamicComp::none && phase_ == Phase::moving && !m.sample_index.empty()) align_delay(m);
  m.trace_samples = m.sample_index.size();
  note_sigma(m, m.sigma_um);
  m.flags = quality_flags(quality_);
  m.degraded = quality_ != 0;
  return m;
}

void note_sigma(Measurement& m, const std::vector<Eigen::Vector3d>& sigma_um) {
  for (const auto& s : sigma_um) {
    if (s.allFinite()) m.sigma_max_um = m.sigma_max_um.cwiseMax(s);
    m.sigma_peak_um = std::max(m.sigma_peak_um, s.maxCoeff());
  }
}

Pipeline::Tracked Pipeline::finish_track(fusion::SegmentSink* sink) {
  if (config_.trace != TraceKeeping::track) throw InputError("pipeline: finish_track() needs TraceKeeping::track");
  Tracked t;
  Measurement& m = t.measurement;
  m = std::move(m_);
  m_ = Measurement{};
  if (!saw_start_) quality_ |= quality_flag::no_start_trigger;
  if (!saw_end_) quality_ |= quality_flag::no_end_trigger;
  m.start_index = start_index_;
  m.motion_end_index = motion_end_index_;
  if (phase_ != Phase::moving) quality_ |= quality_flag::no_motion;
  m.rest_noise = rest_noise_.result();
  t.samples = stored_;
  if (phase_ == Phase::moving && stored_ > 0) {
    const std::int64_t first = first_stored_;
    const SupportStage& stage = supports_;
    t.first_index = first;
    m.supports = supports_.finish_track(
        stored_, [&](std::size_t k) { return stage.trace_index(first, k); }, t.correction, sink);
    Eigen::Vector3d v_rest = Eigen::Vector3d::Zero();
    if (!m.supports.rest_windows.empty() && t.correction) {
      // Rest windows in trace positions again (they are consecutive samples of the trace).
      const RestWindow& last = m.supports.rest_windows.back();
      const std::size_t a = t.correction->position_of(first, last.first_index),
                        b = t.correction->position_of(first, last.last_index);
      const auto [v, cnt] =
          support_velocity_sum(t.correction->schedule.flags, t.correction->track.support_vel_mm_s, a, b);
      if (cnt > 0) v_rest = v / static_cast<double>(cnt);
    }
    rest_windows_done(m, v_rest);
    if (config_.dynamic != DynamicComp::none) t.delay_samples = delay_samples_;
  }
  m.flags = quality_flags(quality_);
  m.degraded = quality_ != 0;
  return t;
}

}  // namespace eical::dsp
