#pragma once
// The error of one axis' integrated motion together with the sensor and machine
// parameters that shape it, in one Kalman filter (augmented state): the integration noise
// is then part of the model and every observation is weighted by what the integration
// could have made of it since the last one — generalised least squares without writing
// down the covariance of a whole run. The parameters are constant states, so after the
// last sample the filter holds their estimate from all the data, with its covariance.
//
//   state  [δx µm, δv µm/s, δb µm/s², θ_1 … θ_p]
//   δv' = δb + Σ_j g_j(t) θ_j + w_a       (parameters acting on the acceleration: scale and
//   δx' = δv                                cross-axis terms, g_j = the acceleration along j)
//   observations  z = δx + Σ h_j θ_j       (parameters seen at the position: 2ζ/ω0 × velocity,
//                 z = δv − lag·δb            rest offsets, backlash, PSD mounting)
#include "dsp/fusion/error_model.hpp"

#include <Eigen/Core>

#include <vector>

namespace eical::dsp::identify {

class AugmentedFilter {
 public:
  // `prior_sigma`: σ of each parameter, `prior_mean` its mean (empty: 0); `start` the INS error's.
  AugmentedFilter(const fusion::ErrorModel& model, const Eigen::Vector3d& start_sigma,
                  const Eigen::VectorXd& prior_sigma, const Eigen::VectorXd& prior_mean = {});

  [[nodiscard]] int parameters() const noexcept { return static_cast<int>(x_.size()) - 3; }
  // One step of h seconds; `accel_gain[j]` = g_j averaged over the step (0 for parameters
  // that do not act on the acceleration); `bias_step` adds the move-start jump.
  void predict(double h_s, const Eigen::VectorXd& accel_gain, bool bias_step);
  // z = row·state + noise (row has 3 + p entries); returns the normalised innovation².
  double update(const Eigen::RowVectorXd& row, double z, double sigma);
  // The innovation and its variance of an observation, without updating (held-out data).
  void predict_observation(const Eigen::RowVectorXd& row, double z, double sigma, double& innovation,
                           double& variance) const;
  // ln of the innovation's density of the last update (for likelihoods).
  [[nodiscard]] double last_log_density() const noexcept { return last_log_density_; }
  [[nodiscard]] double last_innovation() const noexcept { return last_innovation_; }

  [[nodiscard]] const Eigen::VectorXd& state() const noexcept { return x_; }
  [[nodiscard]] const Eigen::MatrixXd& covariance() const noexcept { return p_; }
  [[nodiscard]] double parameter(int j) const { return x_[3 + j]; }
  [[nodiscard]] double parameter_sigma(int j) const;

 private:
  fusion::ErrorModel model_;
  fusion::Discrete step_;  // cached for the last h
  Eigen::VectorXd x_;
  Eigen::MatrixXd p_;
  double last_log_density_ = 0.0, last_innovation_ = 0.0;
};

}  // namespace eical::dsp::identify
