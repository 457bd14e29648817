#pragma once
// Coriolis correction (3-6): a_kor = a_sens − 2 ω × v, with v the sensor's own velocity
// fed back from its first integrator (Bild 3-3). ω is the Earth rate in machine axes
// (3-5): Ω (cos φ · north + sin φ · up), +X at azimuth `heading` (clockwise from north),
// Y at heading − 90°, Z up — the run's [site]. The centrifugal part is constant and goes
// into the rest-window bias (ch. 3.2).
#include "dsp/core/run_meta.hpp"
#include "dsp/core/units.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace eical::dsp {

inline Eigen::Vector3d earth_rate_machine_radps(const Site& site) {
  const double lat_rad = units::deg_to_rad(site.latitude_deg), heading_rad = units::deg_to_rad(site.heading_deg);
  return units::kEarthRateRadps * Eigen::Vector3d(std::cos(lat_rad) * std::cos(heading_rad),
                                                  std::cos(lat_rad) * std::sin(heading_rad), std::sin(lat_rad));
}

struct CoriolisComp {
  Eigen::Vector3d two_omega_radps = Eigen::Vector3d::Zero();  // zero: correction off

  CoriolisComp() = default;
  explicit CoriolisComp(const Site& site) : two_omega_radps(2.0 * earth_rate_machine_radps(site)) {}

  // (3-6)
  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& a_mps2, const Eigen::Vector3d& v_mps) const noexcept {
    return a_mps2 - two_omega_radps.cross(v_mps);
  }
};

}  // namespace eical::dsp
