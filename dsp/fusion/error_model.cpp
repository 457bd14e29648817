#include "dsp/fusion/error_model.hpp"

namespace eical::dsp::fusion {

Discrete discretise(const ErrorModel& m, double h) {
  Discrete d;
  d.h_s = h;
  d.F << 1.0, h, 0.5 * h * h,  //
      0.0, 1.0, h,             //
      0.0, 0.0, 1.0;
  const double qa = m.accel_noise_um_s2_rthz * m.accel_noise_um_s2_rthz;
  const double qb = m.bias_walk_um_s2_rts * m.bias_walk_um_s2_rts;
  const double h2 = h * h, h3 = h2 * h, h4 = h3 * h, h5 = h4 * h;
  d.Q << qa * h3 / 3.0 + qb * h5 / 20.0, qa * h2 / 2.0 + qb * h4 / 8.0, qb * h3 / 6.0,  //
      qa * h2 / 2.0 + qb * h4 / 8.0, qa * h + qb * h3 / 3.0, qb * h2 / 2.0,             //
      qb * h3 / 6.0, qb * h2 / 2.0, qb * h;
  return d;
}

Mat3 initial_covariance(const ErrorModel& m, double start_bias_sigma_um_s2) {
  Mat3 p = Mat3::Zero();
  p(0, 0) = m.start_position_um * m.start_position_um;
  p(1, 1) = m.start_velocity_um_s * m.start_velocity_um_s;
  p(2, 2) = start_bias_sigma_um_s2 * start_bias_sigma_um_s2 + m.bias_step_um_s2 * m.bias_step_um_s2;
  return p;
}

}  // namespace eical::dsp::fusion
