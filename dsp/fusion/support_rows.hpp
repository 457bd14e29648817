#pragma once
// The fusion's support observations (forward_filter.hpp), each as its measurement function
// — what the observation z predicts from one axis' error state e = [δx µm, δv µm/s,
// δb µm/s²] (error_model.hpp) — and the row h that linearises it (z = h·e + noise). The
// filter updates with the rows; tests/dsp/fusion_jacobian_test.cpp checks each against
// central differences of its function.
#include "dsp/fusion/error_model.hpp"

#include <vector>

namespace eical::dsp::fusion::observe {

// ZUPT: the integrated velocity at a standstill (the machine rests: all of it is error).
inline double zupt(const Vec3& e) { return e[1]; }
inline Eigen::RowVector3d zupt_row() { return {0.0, 1.0, 0.0}; }

// NBS: the integrated velocity of an axis the set-point holds.
inline double nbs(const Vec3& e) { return e[1]; }
inline Eigen::RowVector3d nbs_row() { return Eigen::RowVector3d::Unit(1); }

// CUPT: the integrated position minus a PSD strip's reading.
inline double cupt(const Vec3& e) { return e[0]; }
inline Eigen::RowVector3d cupt_row() { return Eigen::RowVector3d::Unit(0); }

// A ringing standstill: the mean integrated velocity over a window of samples ago_s[i]
// seconds before sample k, where the state is e — each the velocity error there by the
// continuous model run back from k (δv' = δb: δv(t_k − τ) = δv_k − τ·δb).
inline double window_mean_velocity(const Vec3& e, const std::vector<double>& ago_s) {
  double sum = 0.0;
  for (double tau : ago_s) sum += e[1] - tau * e[2];
  return sum / static_cast<double>(ago_s.size());
}
// Its row; lag_s: from the window's mean time to sample k (the mean of ago_s).
inline Eigen::RowVector3d velocity_mean_row(double lag_s) { return {0.0, 1.0, -lag_s}; }

}  // namespace eical::dsp::fusion::observe
