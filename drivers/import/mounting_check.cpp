#include "drivers/import/mounting_check.hpp"

#include "sim/sensor/axes_map.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::drivers {
namespace {

// A mean below half a g is not gravity: the recorder removed the sensor's offset.
constexpr double kNoGravityBelow_g = 0.5;

// The 48 signed permutations (rows machine axes, columns sensor axes).
std::vector<Eigen::Matrix3d> signed_permutations() {
  std::vector<Eigen::Matrix3d> out;
  std::array<int, 3> p{0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) m(r, p[static_cast<std::size_t>(r)]) = (signs >> r & 1) ? -1.0 : 1.0;
      out.push_back(m);
    }
  } while (std::next_permutation(p.begin(), p.end()));
  return out;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = a.normalized().dot(b.normalized());
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

std::string vec_text(const Eigen::Vector3d& v) {
  char b[80];
  std::snprintf(b, sizeof b, "[%.2f, %.2f, %.2f]", v.x(), v.y(), v.z());
  return b;
}

// The map that best turns the measured up and motion directions (sensor axes) into the
// machine's, of the stated map's handedness (a chip's axes are right-handed, and so is a
// correct map onto right-handed machine axes: the two measured directions then fix the
// third); among maps the data cannot tell apart, the one closest to the stated map.
Eigen::Matrix3d best_map(const Eigen::Vector3d& up_sensor, const Eigen::Vector3d& motion_sensor,
                         const Eigen::Matrix3d& stated, const Eigen::Vector3d& up, const Eigen::Vector3d& direction) {
  Eigen::Matrix3d best = stated;
  double best_score = -1e9;
  for (const Eigen::Matrix3d& m : signed_permutations()) {
    if (m.determinant() * stated.determinant() < 0.0) continue;
    double score = 0.0;
    if (up_sensor.norm() > 0.0) score += (m * up_sensor.normalized()).dot(up);
    if (motion_sensor.norm() > 0.0) score += (m * motion_sensor.normalized()).dot(direction);
    score += 1e-6 * (m.array() * stated.array()).sum();  // tie-break: agree with the stated map
    if (score > best_score) best_score = score, best = m;
  }
  return best;
}

// The machine axis a direction lies along within kMountingToleranceDeg ("x", "y", "z"; "",
// when none, or along one against the axis' sense).
std::string axis_along(const Eigen::Vector3d& v) {
  for (int a = 0; a < 3; ++a)
    if (angle_deg(v, Eigen::Vector3d::Unit(a)) <= kMountingToleranceDeg)
      return std::string(1, static_cast<char>('x' + a));
  return "";
}

}  // namespace

MountingCheck check_mounting(const Eigen::Vector3d& mean_sensor_g, const Eigen::Matrix3d& gain,
                             const Eigen::Matrix3d& to_machine, const Eigen::Vector3d& direction,
                             const Eigen::Vector3d& up) {
  MountingCheck c;
  c.stated_map = sim::axes_map_text(to_machine);
  c.gravity_g = mean_sensor_g.norm();
  const bool has_gravity = c.gravity_g >= kNoGravityBelow_g;
  const Eigen::Vector3d motion_sensor = gain * direction;
  const bool has_motion = motion_sensor.norm() > 0.0 && std::isfinite(motion_sensor.norm());
  char b[400];
  if (!has_gravity) {
    std::snprintf(b, sizeof b,
                  "the capture's mean is %.3f g, not the 1 g of gravity a sensor reads at rest (its offset removed "
                  "by the recorder?): its scale and vertical axis are not checked",
                  c.gravity_g);
    c.findings.emplace_back(b);
  } else if (std::abs(c.gravity_g - 1.0) > kGravityScaleTolerance) {
    c.scale_fix = 1.0 / c.gravity_g;
    c.consistent = false;
    std::snprintf(b, sizeof b,
                  "the capture's gravity is %.3f g, not 1 g (± %.0f %%, the chips' sensitivity and offset "
                  "tolerances): its values are %.3g times what the sensor measured (e.g. one chip's counts converted "
                  "with another chip's constants); fix: --accel-scale %.4g",
                  c.gravity_g, 100.0 * kGravityScaleTolerance, c.gravity_g, *c.scale_fix);
    c.findings.emplace_back(b);
  }
  const bool up_fits = !has_gravity || angle_deg(to_machine * mean_sensor_g, up) <= kMountingToleranceDeg;
  const bool motion_fits = !has_motion || angle_deg(to_machine * motion_sensor, direction) <= kMountingToleranceDeg;
  if (up_fits && motion_fits) return c;
  const Eigen::Matrix3d fit = best_map(has_gravity ? mean_sensor_g : Eigen::Vector3d::Zero(),
                                       has_motion ? motion_sensor : Eigen::Vector3d::Zero(), to_machine, up, direction);
  const bool fit_fits = (!has_gravity || angle_deg(fit * mean_sensor_g, up) <= kMountingToleranceDeg) &&
                        (!has_motion || angle_deg(fit * motion_sensor, direction) <= kMountingToleranceDeg);
  std::string why = "through the stated mounting " + c.stated_map + ",";
  if (!up_fits) why += " gravity points along machine " + vec_text((to_machine * mean_sensor_g).normalized());
  if (!up_fits && !motion_fits) why += " and";
  if (!motion_fits)
    why += " the commanded motion " + vec_text(direction) + " shows along " +
           vec_text((to_machine * motion_sensor).normalized());
  c.consistent = false;
  // Gravity fits and only the motion does not: the test more likely ran along another axis
  // than the sensor turned about the vertical. Both are named, the axis first.
  const std::string other_axis = up_fits ? axis_along((to_machine * motion_sensor).normalized()) : "";
  if (fit_fits) {
    c.fitting_map = sim::axes_map_text(fit);
    c.findings.push_back(why + "; " +
                         (other_axis.empty() ? ""
                                             : "the test ran along " + other_axis + " (fix: --axis " + other_axis +
                                                   "), or the sensor is turned about the vertical: ") +
                         "the axes map " + c.fitting_map + " fits both gravity (up) and the motion; fix: --mounting " +
                         c.fitting_map);
  } else {
    c.findings.push_back(why + "; no axes map (a signed permutation) fits both within " +
                         std::to_string(static_cast<int>(kMountingToleranceDeg)) +
                         "°: a sensor mounted at an angle, or the wrong --axis or capture");
  }
  return c;
}

}  // namespace eical::drivers
