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

void Pipeline::reset() noexcept {
  phase_ = Phase::wait_start;
  quality_ = 0;
  saw_start_ = saw_end_ = false;
  prev_index_ = -1;
  prev_cmd_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bias_n_ = 0;
  for (int s = 0; s < 2; ++s) last_valid_a_[s] = bias_sum_[s] = bias_[s] = a_prev_[s] = v_[s] = Eigen::Vector3d::Zero();
  v_rel_prev_.setZero();
  x_rel_.setZero();
  start_index_ = motion_end_index_ = -1;
  live_ = LiveEstimate{};
  m_.sample_index.clear();
  for (auto* v : {&m_.pos_mm, &m_.vel_mm_s, &m_.cmd_mm, &m_.ref_mm}) v->clear();
  m_.triggers.clear();
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

void Pipeline::apply_zupt(Measurement& m) {
  // (ch. 3.4.2 / 8.3.1) Zero-velocity updates at every standstill of the set-point: the
  // integrated velocity should be zero there, and what is left is the integral of the
  // acceleration error since the start. Between two standstills the error is taken as
  // linear in time (a constant acceleration error per segment — each partial move its
  // own offset, ch. 8.3.2); after the last one it is held. The correction is removed from
  // the velocity and, integrated, from the position.
  const double fs = config_.acquisition.fs_hz;
  const auto n = m.sample_index.size();
  const auto settle = static_cast<std::size_t>(std::ceil(config_.acquisition.daq_group_delay_samples + config_.zupt_settle_s * fs));
  const auto min_window = static_cast<std::size_t>(0.05 * fs);
  struct Knot {
    double t_s;
    Eigen::Vector3d dv;
  };
  std::vector<Knot> knots{{0.0, Eigen::Vector3d::Zero()}};  // integration starts at rest
  std::size_t i = 0;
  while (i < n) {
    // A stationary stretch of the set-point.
    std::size_t j = i;
    while (j + 1 < n && (m.cmd_mm[j + 1] - m.cmd_mm[i]).cwiseAbs().maxCoeff() < 1e-9 &&
           m.sample_index[j + 1] == m.sample_index[j] + 1)
      ++j;
    if (i > 0 && j - i + 1 >= settle + min_window) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      double t = 0.0;
      for (std::size_t k = i + settle; k <= j; ++k) {
        v += m.vel_mm_s[k];
        t += static_cast<double>(m.sample_index[k] - start_index_) / fs;
      }
      const double cnt = static_cast<double>(j - i - settle + 1);
      knots.push_back({t / cnt, v / cnt});
      m.zupt_window_samples += j - i - settle + 1;
      m.zupt_velocity_error_mm_s = v / cnt;
    }
    i = j + 1;
  }
  if (knots.size() < 2) {
    quality_ |= quality_flag::no_zupt_window;
    return;
  }
  std::size_t seg = 0;
  Eigen::Vector3d pos_corr = Eigen::Vector3d::Zero(), prev_v = Eigen::Vector3d::Zero();
  double prev_t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(m.sample_index[k] - start_index_) / fs;
    while (seg + 1 < knots.size() && t > knots[seg + 1].t_s) ++seg;
    Eigen::Vector3d vc;
    if (seg + 1 < knots.size()) {
      const auto& a = knots[seg];
      const auto& b = knots[seg + 1];
      vc = a.dv + (b.dv - a.dv) * ((t - a.t_s) / (b.t_s - a.t_s));
    } else {
      vc = knots.back().dv;
    }
    if (k > 0) pos_corr += 0.5 * (vc + prev_v) * (t - prev_t);
    prev_v = vc;
    prev_t = t;
    m.vel_mm_s[k] -= vc;
    m.pos_mm[k] -= pos_corr;
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

  if (config_.zupt && phase_ == Phase::moving && !m.sample_index.empty()) apply_zupt(m);
  m.flags = quality_flag_names(quality_);
  m.degraded = quality_ != 0;
  return m;
}

}  // namespace eical::dsp
