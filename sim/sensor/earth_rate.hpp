#pragma once
// Earth rotation in machine axes (3-5): ω = Ω (cos φ · north + sin φ · up), with +X at
// azimuth `heading` (clockwise from north), Y at heading − 90°, Z up. A part moving with
// velocity v feels the Coriolis acceleration 2 ω × v (3-6); the centrifugal part is
// constant and goes into gravity and the bias.
#include "dsp/core/run_meta.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace eical::sim {

inline constexpr double kEarthRate_rad_s = 7.2921159e-5;

inline Eigen::Vector3d earth_rate_machine(const dsp::Site& site) {
  const double phi = site.latitude_deg * std::numbers::pi / 180.0, hd = site.heading_deg * std::numbers::pi / 180.0;
  return kEarthRate_rad_s * Eigen::Vector3d(std::cos(phi) * std::cos(hd), std::cos(phi) * std::sin(hd), std::sin(phi));
}

// Coriolis acceleration (m/s²) of a part moving with v (m/s).
inline Eigen::Vector3d coriolis_mps2(const Eigen::Vector3d& omega_rad_s, const Eigen::Vector3d& v_mps) {
  return 2.0 * omega_rad_s.cross(v_mps);
}

}  // namespace eical::sim
