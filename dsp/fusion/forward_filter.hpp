#pragma once
// The forward Kalman filter over the three machine axes (independent: the static
// compensation has already rotated the sensors into machine axes). The live pipeline runs
// it per sample; the offline smoother runs the same code again over the stored trace.
//
// Resets (as PX4's EKF resets an aid source it keeps rejecting): when a standstill's
// velocity is rejected again and again, the model was too sure of the integration — a
// bias jump it did not expect. The covariance is then opened by what is unexplained
// (P_vv += ν², P_bb += (ν/T)², T since the last accepted velocity) and the update taken.
// The reset is process noise at that sample: the smoother adds it there too (`resets`).
#include "dsp/fusion/axis_filter.hpp"
#include "dsp/fusion/support_rows.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace eical::dsp::fusion {

// Process noise a reset added at sample k (the smoother needs it where the filter did).
struct CovarianceReset {
  std::size_t k = 0;
  int axis = 0;
  double add_vv = 0.0, add_bb = 0.0, add_xx = 0.0;
};

struct ForwardFilter {
  AxisFilter axis[3];
  std::array<std::array<SupportTally, kSupportKinds>, 3> tally{};
  std::size_t k = 0;                               // the sample being processed
  std::vector<CovarianceReset>* resets = nullptr;  // where resets are recorded (within its capacity)
  std::size_t reset_count = 0;

  void start(const ErrorModel& m, const Vec3& start_bias_sigma_um_s2) noexcept {
    for (int a = 0; a < 3; ++a) {
      axis[a].e.setZero();
      axis[a].P = initial_covariance(m, a, start_bias_sigma_um_s2[a]);
    }
    tally = {};
    rejections_ = {}, fix_rejections_ = {};
    since_velocity_s_ = {}, since_position_s_ = {};
    k = reset_count = 0;
  }

  // To the next sample; at the start of a move the bias may jump (ch. 8.3.2).
  void predict(const Discrete& d, bool move_start, const ErrorModel& m) noexcept {
    for (int a = 0; a < 3; ++a) {
      axis[a].predict(d);
      if (move_start) axis[a].P(2, 2) += m.bias_step_um_s2 * m.bias_step_um_s2;
      since_velocity_s_[a] += d.h_s;
      since_position_s_[a] += d.h_s;
    }
  }

  // ZUPT on every axis at a standstill (σ: the model's, or larger where the machine still
  // rings), NBS on the held ones; z = integrated velocity.
  void velocity_supports(std::uint8_t flags, const Vec3& vel_um_s, const ErrorModel& m, double zupt_sigma_um_s = 0.0,
                         bool zupt_on = true) noexcept {
    if (flags & schedule_flag::invalid) return;
    if (zupt_sigma_um_s < 0.0) zupt_on = false;  // a standstill sample whose velocity is not used
    const double sz = std::max(m.zupt_sigma_um_s, zupt_sigma_um_s);
    for (int a = 0; a < 3; ++a) {
      if (flags & schedule_flag::rest) {
        if (zupt_on) velocity_update(a, observe::zupt_row(), vel_um_s[a], sz * sz, m, 1);
      } else if (flags & nbs_flag(a)) {
        tally[a][static_cast<int>(Support::nbs)].add(
            axis[a].update_row(observe::nbs_row(), vel_um_s[a], m.nbs_sigma_um_s * m.nbs_sigma_um_s, m.gate_nis));
      }
    }
  }

  // ZUPT at a ringing standstill: the window's mean velocity.
  void velocity_mean(const VelocityMean& v, const ErrorModel& m, bool zupt_on = true) noexcept {
    if (!zupt_on) return;
    const double s = std::max(m.zupt_sigma_um_s, v.sigma_um_s);
    for (int a = 0; a < 3; ++a) velocity_update(a, observe::velocity_mean_row(v.lag_s), v.mean_um_s[a], s * s, m, 100);
  }

  // CUPT: the integrated position minus the PSD's is the position error (and the scale's
  // share over way_mm, the way from the start along the axis, where the scale is a state;
  // the timing's at the integrated velocity vel_mm_s, where the timing is one).
  // A strip the filter keeps rejecting is reset to like a standstill (the position error is
  // ν; the bias that would have made it since the last position support, 2ν/T²).
  UpdateRecord position_fix(int a, double ins_pos_um, double fix_pos_um, double sigma_um, const ErrorModel& m,
                            double way_mm = 0.0, double vel_mm_s = 0.0) noexcept {
    const double s = sigma_um * sigma_um + m.psd_floor_um * m.psd_floor_um;
    const StateRow h =
        observe::cupt_row(scale_is_a_state(m, a) ? way_mm : 0.0, timing_is_a_state(m, a) ? vel_mm_s : 0.0);
    UpdateRecord r = axis[a].update_row(h, ins_pos_um - fix_pos_um, s, m.gate_nis);
    if (!r.accepted && std::isfinite(r.innovation) && std::abs(r.innovation) < 1e9) {
      if (++fix_rejections_[a] >= m.reset_after_rejections) {
        const double nu = r.innovation, t = std::max(since_position_s_[a], 0.1);
        CovarianceReset reset{k, a, nu * nu * 4.0 / (t * t), 4.0 * nu * nu / (t * t * t * t)};
        reset.add_xx = nu * nu;
        axis[a].P(0, 0) += reset.add_xx;
        axis[a].P(1, 1) += reset.add_vv;
        axis[a].P(2, 2) += reset.add_bb;
        if (resets && resets->size() < resets->capacity()) resets->push_back(reset);
        ++reset_count;
        r = axis[a].update_row(h, ins_pos_um - fix_pos_um, s, m.gate_nis);
      }
    }
    if (r.accepted) fix_rejections_[a] = 0, since_position_s_[a] = 0.0;
    tally[a][static_cast<int>(Support::cupt)].add(r);
    return r;
  }

 private:
  void velocity_update(int a, const StateRow& h, double z, double r, const ErrorModel& m, int weight) noexcept {
    UpdateRecord rec = axis[a].update_row(h, z, r, m.gate_nis);
    if (!rec.accepted && std::isfinite(rec.innovation) && std::abs(rec.innovation) < 1e9) {  // 1 km/s: never a bias
      rejections_[a] += weight;
      if (rejections_[a] >= m.reset_after_rejections) {
        const double nu = rec.innovation, t = std::max(since_velocity_s_[a], 0.1);
        CovarianceReset reset{k, a, nu * nu, (nu / t) * (nu / t)};
        axis[a].P(1, 1) += reset.add_vv;
        axis[a].P(2, 2) += reset.add_bb;
        if (resets && resets->size() < resets->capacity()) resets->push_back(reset);
        ++reset_count;
        rec = axis[a].update_row(h, z, r, m.gate_nis);
      }
    }
    if (rec.accepted) rejections_[a] = 0, since_velocity_s_[a] = 0.0;
    tally[a][static_cast<int>(Support::zupt)].add(rec);
  }

  std::array<int, 3> rejections_{}, fix_rejections_{};
  std::array<double, 3> since_velocity_s_{}, since_position_s_{};
};

}  // namespace eical::dsp::fusion
