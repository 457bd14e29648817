#pragma once
// The error of the integrated relative motion along one machine axis (ch. 5.5: the
// forward, or feed-forward, configuration of Bild 2-6: the integration runs on, the filter
// estimates what it is off by). State e = [δx µm, δv µm/s, δb µm/s², δs ppm, δτ µs]:
// position, velocity and acceleration-bias error of head − table after the rest-window
// bias was removed, the scale error of the integrated way along the axis, and the timing
// error of the integrated path against the strips.
//
//   δx' = δv,   δv' = δb + w_a,   δb' = w_b,   δs' = 0,   δτ' = 0
//
// The scale's share of the integrated position is δs · (way from the start), the timing's
// δτ · v: the damping term 2ζ/ω0 the dynamic compensation (6-38) takes from the sensor
// model shifts the integrated path in time by its error, so a strip crossed at v reads it
// off by v·δτ, the same δτ at every crossing. Both enter where a position is observed
// (support_rows.hpp), never the dynamics, so F stays constant; at rest the true velocity
// is zero and so are both shares of the integrated one. Only axes whose strips span a
// distance observe δs (ErrorModel::scale_state_ppm), only axes with strips δτ
// (ErrorModel::timing_state_us); elsewhere each is a decoupled unit state nothing reads.
//
// w_a: the two sensors' white noise, two-sided density n per sensor (run-format.md), so
// q_a = n_table² + n_head²; w_b: the bias random walk (6-5, 6-6), q_b = walk² (both
// sensors). Exact discretisation over a step h (Van Loan for this chain):
//   F = [1 h h²/2; 0 1 h; 0 0 1] (and 1 for δs)
//   Q = q_a [h³/3 h²/2 0; h²/2 h 0; 0 0 0]
//     + q_b [h⁵/20 h⁴/8 h³/6; h⁴/8 h³/3 h²/2; h³/6 h²/2 h]   (0 for δs)
// Units are µm and seconds so that the covariances stay near 1 (well conditioned).
#include <Eigen/Core>

#include <array>

namespace eical::dsp::fusion {

using Vec3 = Eigen::Vector3d;  // one value per machine axis
using Mat3 = Eigen::Matrix3d;
// One axis' error state [δx, δv, δb, δs, δτ] and its covariance.
inline constexpr int kStates = 5;
inline constexpr int kScaleState = 3;
inline constexpr int kTimingState = 4;
using State = Eigen::Matrix<double, kStates, 1>;
using StateCov = Eigen::Matrix<double, kStates, kStates>;
using StateRow = Eigen::Matrix<double, 1, kStates>;

// What the filter assumes about the sensors and the supports; defaults are the data
// sheet's (SF3000L, ch. 6.2) and what the thesis measured (ch. 8.3.2).
struct ErrorModel {
  double accel_noise_um_s2_rthz = 5.55;  // relative, two-sided: √2 · 0.4 µg/√Hz · g
  double bias_walk_um_s2_rts = 2.0;      // relative bias random walk, ≈ 0.2 µg/√s
  // Each partial move has its own offset (ch. 8.3.2): at every start of a move the bias
  // may jump by this much (σ) from what the rest before it showed.
  double bias_step_um_s2 = 20.0;     // ≈ 2 µg
  double start_position_um = 2.0;    // σ of the start position against the set-point
  double start_velocity_um_s = 1.0;  // σ of the velocity at the start (at rest)
  double zupt_sigma_um_s = 2.0;      // σ of the velocity at a standstill (vibration, creep)
  double zupt_onset_skip_s = 0.1;    // offline: a standstill's first 0.1 s (settling) unused
  double nbs_sigma_um_s = 5.0;       // σ of a held axis' velocity (straightness, vibration)
  double psd_floor_um = 0.05;        // added to every PSD fix's σ (model error of the strip)
  // The sensors' scale and mounting are known to this (relative, data sheet: a few 1e-4;
  // identified on site: a few 1e-5): a PSD fix d mm from where the integration started
  // cannot be trusted closer than this times d — the error there is no wandering bias.
  double scale_uncertainty = 3e-4;
  // The start position is given in the set-point's frame, a strip's readings in the strip's;
  // integrated from one to the other they differ by the scale error over the way between
  // (on one run only the first pass sees both, so anchoring it to both invents repeatability).
  // Per axis: the σ of that difference, scale_uncertainty × the distance from the start to
  // the nearest strip on the axis (SupportStage sets it; zero without strips).
  std::array<double, 3> start_frame_um{};
  // Per axis: σ (ppm) of the scale error as a state of the filter, which strips at different
  // places along the axis observe (two readings d mm apart differ by δs·d); 0: no such
  // strips, the scale stays in each reading's model σ. SupportStage sets it from the strips.
  std::array<double, 3> scale_state_ppm{};
  // Per axis: σ (s) of the sensor model's timing, the damping term of the sensor that
  // carries the axis and the DAQ's delay (data sheet or identification;
  // dsp::timing_sigma_s). pipeline_config() sets it.
  std::array<double, 3> timing_uncertainty_s{};
  // Per axis: σ (µs) of the timing error as a state of the filter, which the strips on the
  // axis observe where they are crossed at speed; 0: no strips, no state. SupportStage
  // sets it from the strips and timing_uncertainty_s.
  std::array<double, 3> timing_state_us{};
  double gate_nis = 25.0;  // innovation test: reject beyond 5 σ
  // A standstill whose velocity the filter keeps rejecting means the model was too sure
  // (a bias jump it did not expect): after this many rejections in a row (per-sample
  // ZUPT; a window mean counts 100) the covariance is opened by what was unexplained.
  int reset_after_rejections = 100;
};

// True when the model keeps axis a's scale as a state (ErrorModel::scale_state_ppm).
inline bool scale_is_a_state(const std::array<double, 3>& scale_state_ppm, int a) noexcept {
  return scale_state_ppm[static_cast<std::size_t>(a)] > 0.0;
}
inline bool scale_is_a_state(const ErrorModel& model, int a) noexcept {
  return scale_is_a_state(model.scale_state_ppm, a);
}
// True when the model keeps axis a's timing as a state (ErrorModel::timing_state_us).
inline bool timing_is_a_state(const ErrorModel& model, int a) noexcept {
  return model.timing_state_us[static_cast<std::size_t>(a)] > 0.0;
}
// True when a position reading depends on where and how fast the axis moved (the scale or
// the timing is a state on some axis): the schedule then carries the way.
inline bool reads_the_way(const ErrorModel& model) noexcept {
  for (int a = 0; a < 3; ++a)
    if (scale_is_a_state(model, a) || timing_is_a_state(model, a)) return true;
  return false;
}

struct Discrete {
  StateCov F = StateCov::Identity();
  StateCov Q = StateCov::Zero();
  double h_s = 0.0;
};

Discrete discretise(const ErrorModel& model, double h_s);

// Covariance of one axis' error at the start of the motion: the start position against
// the set-point (and the strips' frame), the velocity at rest, the rest-window bias (σ
// given) and its jump into the first move, the scale and the timing (1 where no state).
StateCov initial_covariance(const ErrorModel& model, int axis, double start_bias_sigma_um_s2);

}  // namespace eical::dsp::fusion
