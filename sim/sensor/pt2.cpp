#include "sim/sensor/pt2.hpp"

#include "dsp/core/error.hpp"

#include <numbers>

namespace eical::sim {

Pt2::Pt2(double f0_hz, double zeta, double step_s) {
  if (!(f0_hz > 0.0) || !(zeta > 0.0) || !(step_s > 0.0))
    throw dsp::InputError("PT2: f0, zeta and step must be positive");
  const double w = 2.0 * std::numbers::pi * f0_hz;
  // Augmented system [x; u]' = [A B; 0 0][x; u]: its exponential holds Φ and Γ.
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  M(0, 1) = 1.0;
  M(1, 0) = -w * w;
  M(1, 1) = -2.0 * zeta * w;
  M(1, 2) = w * w;
  M *= step_s;
  // Scaling and squaring with a Taylor series: ‖M‖ is ~0.1 at 100 kHz, so 2^4 scaling and
  // 16 terms are far below double precision.
  const int squarings = 4;
  const Eigen::Matrix3d Ms = M / static_cast<double>(1 << squarings);
  Eigen::Matrix3d E = Eigen::Matrix3d::Identity(), term = Eigen::Matrix3d::Identity();
  for (int k = 1; k <= 16; ++k) {
    term = term * Ms / static_cast<double>(k);
    E += term;
  }
  for (int k = 0; k < squarings; ++k) E = E * E;
  phi_ = E.topLeftCorner<2, 2>();
  gamma_ = E.block<2, 1>(0, 2);
}

}  // namespace eical::sim
