#include "dsp/pipeline/pipeline.hpp"

#include <cmath>

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
  c.capacity_samples = capacity_samples;
  return c;
}

std::vector<std::string> quality_flag_names(std::uint32_t bits) {
  static const char* const names[] = {
      "accel_missing: acceleration samples missing (last value held)",
      "accel_saturated: ADC at full scale (last valid value held)",
      "frames_lost: the DAQ or driver lost frames (gap integrated with the last value)",
      "not_finite: NaN or Inf in a sample (last valid value held)",
      "no_start_trigger: no M101 (101) trigger; rest window taken from the start of the data",
      "no_motion: the set-point never moved",
      "short_rest_window: fewer than 0.1 s at rest before the motion (bias uncertain)",
      "no_zupt_window: no rest after the motion (velocity drift not removed)",
      "capacity_exceeded: the measurement is longer than the trace capacity (end cut off)",
      "no_end_trigger: no M103 (103) trigger; the measurement ends with the data",
  };
  std::vector<std::string> out;
  for (std::uint32_t b = 0; b < std::size(names); ++b)
    if (bits & (1u << b)) out.emplace_back(names[b]);
  return out;
}

Pipeline::Pipeline(const PipelineConfig& c) : config_(c), dt_s_(1.0 / c.acquisition.fs_hz) {
  const double delay_s = c.acquisition.daq_group_delay_samples / c.acquisition.fs_hz;
  for (int s = 0; s < 2; ++s) {
    comp_[s] = StaticComp(c.sensors[s], c.acquisition, c.site);
    dyn_[s] = dynamic_coefficients(c.sensors[s], delay_s, c.dynamic);
    last_valid_a_[s] = bias_sum_[s] = bias_[s] = a_prev_[s] = v_[s] = Eigen::Vector3d::Zero();
  }
  m_.fs_hz = c.acquisition.fs_hz;
  for (auto* v : {&m_.pos_mm, &m_.vel_mm_s, &m_.cmd_mm, &m_.ref_mm}) v->reserve(c.capacity_samples);
  m_.sample_index.reserve(c.capacity_samples);
  m_.triggers.reserve(trigger_capacity_);
}

void Pipeline::store(const Frame& f, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s) noexcept {
  if (m_.sample_index.size() >= config_.capacity_samples) {
    quality_ |= quality_flag::capacity_exceeded;
    return;
  }
  m_.sample_index.push_back(f.sample_index);  // within the reserve: no allocation
  m_.pos_mm.push_back(pos_mm);
  m_.vel_mm_s.push_back(vel_mm_s);
  m_.cmd_mm.emplace_back(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  m_.ref_mm.emplace_back(f.ref_mm[0], f.ref_mm[1], f.ref_mm[2]);
}

void Pipeline::step(const Frame& f) noexcept {
  // Quality of this frame; bad accelerations are replaced by the last valid ones.
  if (f.flags & frame_flag::accel_missing) quality_ |= quality_flag::accel_missing;
  if (f.flags & frame_flag::accel_saturated) quality_ |= quality_flag::accel_saturated;
  if (f.flags & frame_flag::not_finite) quality_ |= quality_flag::not_finite;
  if (f.flags & frame_flag::gap_before) quality_ |= quality_flag::frames_lost;
  Eigen::Vector3d a[2];
  for (int s = 0; s < 2; ++s) {
    if (f.flags & kAccelBad) {
      a[s] = last_valid_a_[s];
    } else {
      a[s] = comp_[s].apply(&f.accel_counts[3 * s]);
      last_valid_a_[s] = a[s];
    }
  }
  const double dt = prev_index_ >= 0 ? static_cast<double>(f.sample_index - prev_index_) * dt_s_ : dt_s_;
  prev_index_ = f.sample_index;
  if (f.trigger != 0 && m_.triggers.size() < trigger_capacity_) m_.triggers.push_back({f.sample_index, f.trigger});
  if (f.trigger == 101) saw_start_ = true;
  if (f.trigger == 103) saw_end_ = true;

  const Eigen::Vector3d cmd(f.cmd_mm[0], f.cmd_mm[1], f.cmd_mm[2]);
  const bool cmd_valid = !(f.flags & frame_flag::cmd_missing) && cmd.allFinite();
  const bool cmd_moved = cmd_valid && prev_cmd_.allFinite() && cmd != prev_cmd_;
  if (cmd_valid) prev_cmd_ = cmd;
  live_.sample_index = f.sample_index;

  switch (phase_) {
    case Phase::wait_start:
      if (f.trigger != 101) return;
      phase_ = Phase::rest;
      [[fallthrough]];
    case Phase::rest:
      if (!cmd_moved) {
        for (int s = 0; s < 2; ++s) bias_sum_[s] += a[s];
        ++bias_n_;
        return;
      }
      // First motion of the set-point: the sensors (delayed by d) still see the rest,
      // so the rest mean is the bias; integration starts here at the set-point.
      for (int s = 0; s < 2; ++s) {
        bias_[s] = bias_n_ > 0 ? Eigen::Vector3d(bias_sum_[s] / static_cast<double>(bias_n_)) : a[s];
        a_prev_[s] = a[s] - bias_[s];
        v_[s].setZero();
      }
      if (bias_n_ < static_cast<std::size_t>(0.1 / dt_s_)) quality_ |= quality_flag::short_rest_window;
      m_.rest_bias_rel_mps2 = bias_[1] - bias_[0];
      m_.rest_window_samples = bias_n_;
      start_pos_mm_ = prev_cmd_;
      start_index_ = motion_end_index_ = f.sample_index;
      v_rel_prev_.setZero();
      x_rel_.setZero();
      phase_ = Phase::moving;
      live_.integrating = true;
      store(f, start_pos_mm_, Eigen::Vector3d::Zero());
      return;
    case Phase::moving: {
      if (cmd_moved) motion_end_index_ = f.sample_index;
      Eigen::Vector3d x_kor = Eigen::Vector3d::Zero(), v_kor = Eigen::Vector3d::Zero();
      for (int s = 0; s < 2; ++s) {
        const Eigen::Vector3d as = a[s] - bias_[s];
        v_[s] += 0.5 * (as + a_prev_[s]) * dt;  // trapezoid
        // Head counts +, table − (relative motion head − table, 3-1); (6-38) per sensor.
        const double sign = s == 1 ? 1.0 : -1.0;
        x_kor += sign * (dyn_[s].c1_s * v_[s] + dyn_[s].c2_s2 * as);
        v_kor += sign * dyn_[s].c1_s * as;
        a_prev_[s] = as;
      }
      const Eigen::Vector3d v_rel = v_[1] - v_[0];
      x_rel_ += 0.5 * (v_rel + v_rel_prev_) * dt;
      v_rel_prev_ = v_rel;
      const Eigen::Vector3d pos_mm = start_pos_mm_ + (x_rel_ + x_kor) * 1000.0;
      const Eigen::Vector3d vel_mm_s = (v_rel + v_kor) * 1000.0;
      live_.pos_mm = pos_mm;
      live_.vel_mm_s = vel_mm_s;
      store(f, pos_mm, vel_mm_s);  // frames after M103 belong to the rest (ZUPT) window too
      return;
    }
  }
}

Measurement Pipeline::finish() {
  Measurement m = std::move(m_);
  m_ = Measurement{};
  if (!saw_start_) quality_ |= quality_flag::no_start_trigger;
  if (!saw_end_) quality_ |= quality_flag::no_end_trigger;
  m.start_index = start_index_;
  m.motion_end_index = motion_end_index_;
  if (phase_ != Phase::moving) quality_ |= quality_flag::no_motion;

  if (config_.zupt && phase_ == Phase::moving && !m.sample_index.empty()) {
    // ZUPT window: from the end of the motion + DAQ delay + settling to the end (M103
    // and the post-trigger frames are all at rest).
    const double fs = config_.acquisition.fs_hz;
    const auto from = motion_end_index_ +
                      static_cast<std::int64_t>(std::ceil(config_.acquisition.daq_group_delay_samples + config_.zupt_settle_s * fs));
    Eigen::Vector3d v_sum = Eigen::Vector3d::Zero();
    double t_sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
      if (m.sample_index[i] < from) continue;
      v_sum += m.vel_mm_s[i];
      t_sum += static_cast<double>(m.sample_index[i] - start_index_) / fs;
      ++n;
    }
    m.zupt_window_samples = n;
    if (n >= static_cast<std::size_t>(0.05 * fs)) {
      // (ch. 3.4.2) a constant acceleration error b since the start makes the velocity
      // grow as b·t: the mean velocity over the window at its mean time t_z gives b.
      const Eigen::Vector3d dv = v_sum / static_cast<double>(n);
      const double tz = t_sum / static_cast<double>(n);
      const Eigen::Vector3d b = dv / tz;  // mm/s²
      m.zupt_velocity_error_mm_s = dv;
      for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
        const double t = static_cast<double>(m.sample_index[i] - start_index_) / fs;
        m.vel_mm_s[i] -= b * t;
        m.pos_mm[i] -= b * (t * t / 2.0);
      }
    } else {
      quality_ |= quality_flag::no_zupt_window;
    }
  }
  m.flags = quality_flag_names(quality_);
  m.degraded = quality_ != 0;
  return m;
}

}  // namespace eical::dsp
