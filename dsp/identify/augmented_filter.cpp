#include "dsp/identify/augmented_filter.hpp"

#include <cmath>
#include <numbers>

namespace eical::dsp::identify {

AugmentedFilter::AugmentedFilter(const fusion::ErrorModel& model, const Eigen::Vector3d& start_sigma,
                                 const Eigen::VectorXd& prior_sigma, const Eigen::VectorXd& prior_mean)
    : model_(model) {
  const Eigen::Index n = 3 + prior_sigma.size();
  x_ = Eigen::VectorXd::Zero(n);
  p_ = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < 3; ++i) p_(i, i) = start_sigma[i] * start_sigma[i];
  for (Eigen::Index j = 0; j < prior_sigma.size(); ++j) p_(3 + j, 3 + j) = prior_sigma[j] * prior_sigma[j];
  if (prior_mean.size() == prior_sigma.size()) x_.tail(prior_mean.size()) = prior_mean;
}

void AugmentedFilter::predict(double h_s, const Eigen::VectorXd& accel_gain, bool bias_step) {
  // F = I except: δx += h δv + h²/2 (δb + g·θ), δv += h (δb + g·θ). Applied as P ← F P Fᵀ
  // through its two rows (F differs from I only there).
  const Eigen::Index n = x_.size(), p = n - 3;
  Eigen::RowVectorXd fx = Eigen::RowVectorXd::Zero(n), fv = Eigen::RowVectorXd::Zero(n);
  fx[0] = 1.0, fx[1] = h_s, fx[2] = 0.5 * h_s * h_s;
  fv[1] = 1.0, fv[2] = h_s;
  fx.tail(p) = 0.5 * h_s * h_s * accel_gain.transpose();
  fv.tail(p) = h_s * accel_gain.transpose();
  const double nx = fx.dot(x_), nv = fv.dot(x_);
  x_[0] = nx, x_[1] = nv;
  // Rows 0 and 1 of F·P, then columns 0 and 1 of (F·P)·Fᵀ.
  const Eigen::RowVectorXd r0 = fx * p_, r1 = fv * p_;
  p_.row(0) = r0;
  p_.row(1) = r1;
  const Eigen::VectorXd c0 = p_ * fx.transpose(), c1 = p_ * fv.transpose();
  p_.col(0) = c0;
  p_.col(1) = c1;
  if (h_s != step_.h_s) step_ = fusion::discretise(model_, h_s);
  p_.topLeftCorner<3, 3>() += step_.Q.topLeftCorner<3, 3>();
  if (bias_step) p_(2, 2) += model_.bias_step_um_s2 * model_.bias_step_um_s2;
  p_ = 0.5 * (p_ + p_.transpose()).eval();
}

double AugmentedFilter::update(const Eigen::RowVectorXd& row, double z, double sigma) {
  const Eigen::VectorXd ph = p_ * row.transpose();
  const double s = row.dot(ph) + sigma * sigma;
  if (!(s > 0.0) || !std::isfinite(z)) return 0.0;
  const double nu = z - row.dot(x_);
  last_innovation_ = nu;
  last_log_density_ = -0.5 * (nu * nu / s + std::log(2.0 * std::numbers::pi * s));
  const Eigen::VectorXd k = ph / s;
  x_ += k * nu;
  p_ -= k * ph.transpose();
  p_ = 0.5 * (p_ + p_.transpose()).eval();
  return nu * nu / s;
}

void AugmentedFilter::predict_observation(const Eigen::RowVectorXd& row, double z, double sigma, double& innovation,
                                          double& variance) const {
  innovation = z - row.dot(x_);
  variance = row.dot(p_ * row.transpose()) + sigma * sigma;
}

double AugmentedFilter::parameter_sigma(int j) const { return std::sqrt(std::max(0.0, p_(3 + j, 3 + j))); }

}  // namespace eical::dsp::identify
