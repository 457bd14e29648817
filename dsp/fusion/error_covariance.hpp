#pragma once
// The noise-limited accuracy of a measurement: the posterior covariance of the position
// error that the sensor noise leaves with the supports the measurement had. For a linear
// Gaussian model it is the smallest error covariance any unbiased estimator reaches
// (Cramér–Rao), and the RTS smoother reaches it. Between two samples j < k
//   Cov(x_j, x_k | all) = C_j C_{j+1} … C_{k−1} P_k|N        (C: the smoother's gains)
// so any linear evaluation of the trace (a radius deviation after a centre fit, an end
// position, the mean of repeats) has its noise-limited variance as a quadratic form.
//
// The covariance does not depend on the data, only on the schedule of supports; the
// model's gate is off (every support taken) and the start is exact (the trace is measured
// from where it starts).
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace eical::dsp::fusion {

class ErrorCovariance {
 public:
  // The schedule's trace: sample indices (gaps widen a step), fs.
  ErrorCovariance(const SupportSchedule& schedule, const std::vector<std::int64_t>& sample_index, double fs_hz,
                  ErrorModel model, const Vec3& start_bias_sigma_um_s2);

  // Position error covariance (µm²) of `axis` between every pair of the given trace
  // positions (ascending).
  [[nodiscard]] Eigen::MatrixXd position(const std::vector<std::size_t>& at, int axis) const;
  [[nodiscard]] double sigma_um(std::size_t k, int axis) const;

 private:
  std::array<std::vector<StateCov>, 3> gain_, p_;
};

}  // namespace eical::dsp::fusion
