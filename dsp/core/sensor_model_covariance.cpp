#include "dsp/core/sensor_model_covariance.hpp"

#include <cmath>
#include <numbers>

namespace eical::dsp {
namespace {

constexpr const char* kSensor[2] = {"table", "head"};
constexpr const char* kAxis = "xyz";

}  // namespace

std::string parameter_name(int p) {
  if (p >= 0 && p < 18) {
    const int s = p / 9, i = (p % 9) / 3, j = p % 3;
    return std::string(kSensor[s]) + ".E_" + kAxis[i] + kAxis[j];
  }
  if (p == damping_index(0) || p == damping_index(1)) return std::string(kSensor[p - 18]) + ".c1_s";
  if (p == kDelayIndex) return "daq.delay_s";
  if (p >= 21 && p < kModelParameters)
    return std::string(kSensor[(p - 21) / 3]) + ".tc_bias_" + kAxis[(p - 21) % 3] + "_ug_per_c";
  return "?";
}

int parameter_index(const std::string& name) {
  for (int p = 0; p < kModelParameters; ++p)
    if (parameter_name(p) == name) return p;
  return -1;
}

SensorModelCovariance datasheet_covariance(const SensorSpec sensors[2], double fs_hz,
                                           const DatasheetTolerance& tolerance) {
  SensorModelCovariance c;
  c.source = "datasheet";
  const double third = 1.0 / 3.0;  // uniform within ±a: u² = a²/3
  for (int s = 0; s < 2; ++s) {
    // The vertical axis' slope errors of k2, k3 at 1 g (sensor axis 3 ≈ machine z).
    const double k2 = 2.0 * tolerance.k2_k3_relative * std::abs(sensors[s].k2_g_per_g2[2]),
                 k3 = 3.0 * tolerance.k2_k3_relative * std::abs(sensors[s].k3_g_per_g3[2]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double v =
            (tolerance.cross_g_per_g * tolerance.cross_g_per_g + tolerance.mounting_rad * tolerance.mounting_rad) *
            third;
        if (i == j)
          v = (tolerance.scale * tolerance.scale +
               (i < 2 ? tolerance.cross2_g_per_g2 * tolerance.cross2_g_per_g2 : k2 * k2 + k3 * k3)) *
              third;
        c.covariance(error_index(s, i, j), error_index(s, i, j)) = v;
      }
    // c1 = 2ζ/ω0 = ζ/(π f0): δc1 = δζ/(π f0) − c1 δf0/f0.
    const double f0 = sensors[s].f0_hz, c1 = sensors[s].zeta / (std::numbers::pi * f0);
    const double u_zeta = tolerance.zeta / (std::numbers::pi * f0), u_f0 = c1 * tolerance.f0_relative;
    c.covariance(damping_index(s), damping_index(s)) = (u_zeta * u_zeta + u_f0 * u_f0) * third;
    for (int i = 0; i < 3; ++i)
      c.covariance(tc_bias_index(s, i), tc_bias_index(s, i)) =
          tolerance.tc_bias_ug_per_c * tolerance.tc_bias_ug_per_c * third;
  }
  const double d_s = tolerance.delay_samples / fs_hz;
  c.covariance(kDelayIndex, kDelayIndex) = d_s * d_s * third;
  return c;
}

std::array<double, 3> timing_sigma_s(const SensorModelCovariance& c, const std::array<int, 3>& owner) {
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    const double damping_var = owner[i] >= 0 ? c.covariance(damping_index(owner[i]), damping_index(owner[i])) : 0.0;
    out[i] = std::sqrt(std::max(0.0, damping_var + c.covariance(kDelayIndex, kDelayIndex)));
  }
  return out;
}

}  // namespace eical::dsp
