#include "dsp/fusion/error_model.hpp"

namespace eical::dsp::fusion {

Discrete discretise(const ErrorModel& model, double h_s) {
  Discrete d;
  d.h_s = h_s;
  d.F.topLeftCorner<3, 3>() << 1.0, h_s, 0.5 * h_s * h_s,  //
      0.0, 1.0, h_s,                                       //
      0.0, 0.0, 1.0;
  const double qa = model.accel_noise_um_s2_rthz * model.accel_noise_um_s2_rthz;
  const double qb = model.bias_walk_um_s2_rts * model.bias_walk_um_s2_rts;
  const double h2 = h_s * h_s, h3 = h2 * h_s, h4 = h3 * h_s, h5 = h4 * h_s;
  d.Q.topLeftCorner<3, 3>() << qa * h3 / 3.0 + qb * h5 / 20.0, qa * h2 / 2.0 + qb * h4 / 8.0, qb * h3 / 6.0,  //
      qa * h2 / 2.0 + qb * h4 / 8.0, qa * h_s + qb * h3 / 3.0, qb * h2 / 2.0,                                 //
      qb * h3 / 6.0, qb * h2 / 2.0, qb * h_s;
  return d;
}

StateCov initial_covariance(const ErrorModel& model, int axis, double start_bias_sigma_um_s2) {
  StateCov p = StateCov::Zero();
  const double frame_um = model.start_frame_um[static_cast<std::size_t>(axis)];
  p(0, 0) = model.start_position_um * model.start_position_um + frame_um * frame_um;
  p(1, 1) = model.start_velocity_um_s * model.start_velocity_um_s;
  p(2, 2) = start_bias_sigma_um_s2 * start_bias_sigma_um_s2 + model.bias_step_um_s2 * model.bias_step_um_s2;
  const double scale_ppm = model.scale_state_ppm[static_cast<std::size_t>(axis)];
  p(kScaleState, kScaleState) = scale_ppm > 0.0 ? scale_ppm * scale_ppm : 1.0;
  const double timing_us = model.timing_state_us[static_cast<std::size_t>(axis)];
  p(kTimingState, kTimingState) = timing_us > 0.0 ? timing_us * timing_us : 1.0;
  return p;
}

}  // namespace eical::dsp::fusion
