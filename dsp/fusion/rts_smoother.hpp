#pragma once
// Offline fusion of a whole measurement: the forward Kalman filter of the live path run
// again over the stored trace with the refined support schedule, then the Rauch–Tung–
// Striebel backward pass over the same state model (error_model.hpp). The result is the
// smoothed error of the integrated position and velocity per sample and axis, its
// posterior σ, and a tally of every support update.
//
// RTS (x̂, P filtered; x̂⁻, P⁻ predicted):
//   C_k = P_k Fᵀ (P⁻_{k+1})⁻¹
//   x̂_k|N = x̂_k + C_k (x̂_{k+1}|N − x̂⁻_{k+1}),   P_k|N = P_k + C_k (P_{k+1}|N − P⁻_{k+1}) C_kᵀ
// The posterior covariance of the linear-Gaussian model is the smallest error any
// unbiased estimator reaches with these supports (Cramér–Rao): it is the noise-limited
// bound the accuracy benchmark quotes (`cross_covariance_chain` gives it between samples).
#include "dsp/core/sample_rate.hpp"
#include "dsp/fusion/axis_filter.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace eical::dsp::fusion {

struct SmootherInput {
  const std::vector<std::int64_t>* sample_index = nullptr;  // gaps (lost frames) widen the step
  const std::vector<Eigen::Vector3d>* vel_mm_s = nullptr;   // integrated relative velocity
  const std::vector<Eigen::Vector3d>* pos_mm = nullptr;     // integrated relative position
  const SupportSchedule* schedule = nullptr;
  double fs_hz = kDefaultFs_hz;
  ErrorModel model;
  Vec3 start_bias_sigma_um_s2 = Vec3::Constant(20.0);  // σ of the rest-window bias per axis
  bool keep_gains = false;                             // keep C_k (for cross-time covariances: the accuracy bound)
  bool forward_only = false;                           // the live filter's causal result, no backward pass
};

struct SmootherOutput {
  std::vector<Eigen::Vector3d> dx_um, dv_um_s;                     // smoothed error per sample (subtract it)
  std::vector<Eigen::Vector3d> sigma_x_um;                         // posterior σ of the position per axis
  std::vector<Eigen::Vector3d> bias_um_s2;                         // smoothed residual bias per axis
  std::array<std::array<SupportTally, kSupportKinds>, 3> tally{};  // [axis][support]
  std::size_t resets = 0;  // covariance resets of the forward pass (forward_filter.hpp)
  // keep_gains: per axis and sample, C_k and the smoothed covariance P_k|N.
  std::array<std::vector<StateCov>, 3> gain, p_smoothed;
};

// Throws InputError when the arrays disagree in length. Runs the checkpointed smoother
// (checkpointed_smoother.hpp) and gathers its segments: the same numbers, in memory.
SmootherOutput smooth(const SmootherInput& in);

struct SmootherTrack;
// The compact track of a stored trace (what the checkpointed smoother reads).
SmootherTrack smoother_track(const std::vector<std::int64_t>& sample_index,
                             const std::vector<Eigen::Vector3d>& vel_mm_s, const std::vector<Eigen::Vector3d>& pos_mm,
                             const SupportSchedule& schedule);

}  // namespace eical::dsp::fusion
