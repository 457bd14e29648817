#include "sim/sensor/sensing_element.hpp"

#include "dsp/core/error.hpp"
#include "sim/sensor/pt2.hpp"

#include <cmath>
#include <numbers>

namespace eical::sim {
namespace {

// PT2 with ζ = ζ0 (1 + k |a − a_rest|): the coefficients change every step, so classic
// RK4 on the state (y, y') with the input held over the step (error ~ (ω0 h)^5 / 120, i.e.
// 1e-8 of the signal at 1 kHz and 100 kHz).
void pt2_amplitude_damped(std::vector<double>& x, double f0_hz, double zeta0, double zeta_per_g, double h) {
  const double w = 2.0 * std::numbers::pi * f0_hz, w2 = w * w;
  const double rest = x[0];
  double y = x[0], dy = 0.0, prev = x[0];
  for (std::size_t k = 1; k < x.size(); ++k) {
    const double u = 0.5 * (prev + x[k]);
    prev = x[k];
    const double zeta = zeta0 * (1.0 + zeta_per_g * std::abs(u - rest));
    auto f = [&](double yy, double vv) { return w2 * (u - yy) - 2.0 * zeta * w * vv; };
    const double k1y = dy, k1v = f(y, dy);
    const double k2y = dy + 0.5 * h * k1v, k2v = f(y + 0.5 * h * k1y, dy + 0.5 * h * k1v);
    const double k3y = dy + 0.5 * h * k2v, k3v = f(y + 0.5 * h * k2y, dy + 0.5 * h * k2v);
    const double k4y = dy + h * k3v, k4v = f(y + h * k3y, dy + h * k3v);
    y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
    dy += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    x[k] = y;
  }
}

void pt2_constant(std::vector<double>& x, double f0_hz, double zeta, double h) {
  Pt2 pt2(f0_hz, zeta, h);
  pt2.settle(x[0]);
  double prev = x[0];
  for (std::size_t k = 1; k < x.size(); ++k) {
    const double u = 0.5 * (prev + x[k]);  // the input over the step, second-order accurate
    prev = x[k];
    x[k] = pt2.step(u);
  }
}

}  // namespace

void sense(std::array<std::vector<double>, 3>& axes_g, const SensorTruth& sensor, double step_s) {
  if (axes_g[1].size() != axes_g[0].size() || axes_g[2].size() != axes_g[0].size() || axes_g[0].empty())
    throw dsp::InputError("sensor model: the three axes need the same, non-zero number of samples");
  for (auto& axis : axes_g) {
    if (sensor.zeta_per_g != 0.0)
      pt2_amplitude_damped(axis, sensor.spec.f0_hz, sensor.spec.zeta, sensor.zeta_per_g, step_s);
    else
      pt2_constant(axis, sensor.spec.f0_hz, sensor.spec.zeta, step_s);
  }
  // (6-4) without bias and noise: a_i + k2 a_i² + k3 a_i³ + Σ_j kx_ij a_j + Σ_j kxx_ij a_i a_j.
  const Eigen::Vector3d& k2 = sensor.spec.k2_g_per_g2;
  const Eigen::Vector3d& k3 = sensor.spec.k3_g_per_g3;
  const Eigen::Matrix3d& kx = sensor.k_cross_g_per_g;
  const Eigen::Matrix3d& kxx = sensor.k_cross2_g_per_g2;
  const bool cross = kx.squaredNorm() > 0.0 || kxx.squaredNorm() > 0.0;
  const std::size_t n = axes_g[0].size();
  for (std::size_t k = 0; k < n; ++k) {
    const double v[3] = {axes_g[0][k], axes_g[1][k], axes_g[2][k]};
    for (int i = 0; i < 3; ++i) {
      double u = v[i] + k2[i] * v[i] * v[i] + k3[i] * v[i] * v[i] * v[i];
      if (cross)
        for (int j = 0; j < 3; ++j)
          if (j != i) u += kx(i, j) * v[j] + kxx(i, j) * v[i] * v[j];
      axes_g[static_cast<std::size_t>(i)][k] = u;
    }
  }
}

}  // namespace eical::sim
