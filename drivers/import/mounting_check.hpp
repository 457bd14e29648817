#pragma once
// What gravity and the commanded motion say about a capture's scale and axes (issue 34).
// At rest, and on average over a test that ends where it starts, a sensor reads the
// reaction to gravity: 1 g along the machine's up axis. Its magnitude checks the scale a
// recorder applied (Klipper converting one chip's counts with another's constants records
// 8 g), its direction the vertical axis of the mounting; the direction in which the
// commanded acceleration shows fixes the rest of the axes map. Together they name the
// mounting that fits, in the notation `--mounting` takes.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace eical::drivers {

// The capture's gravity may lie this far from 1 g before its scale is called wrong: the
// MEMS chips' sensitivity (±10 %) and 0-g offset (±150 mg on z) tolerances of their data
// sheets (sim/sensor/mems_chip.hpp), added.
inline constexpr double kGravityScaleTolerance = 0.25;
// A stated axis counts as fitting when the measured direction lies within this angle of it:
// a printer's sensor mount is tilted by a few degrees, never by half a right angle.
inline constexpr double kMountingToleranceDeg = 30.0;

struct MountingCheck {
  double gravity_g = 0.0;             // |mean| of the capture, in g of the site
  std::optional<double> scale_fix;    // multiply the recording by this (gravity → 1 g)
  std::string stated_map;             // --mounting as stated
  std::string fitting_map;            // the signed permutation that fits; "" when none does
  std::vector<std::string> findings;  // each names the cause and, where known, the fix
  bool consistent = true;             // false: the scale or the axes map contradicts gravity or the motion
};

// mean_sensor_g: the capture's mean (sensor axes, g); gain: measured (sensor axes, g) per
// commanded (machine axes, mm/s²) from the offset estimate; to_machine: the stated mounting;
// direction: the commanded unit direction; up: the machine's up axis (unit).
MountingCheck check_mounting(const Eigen::Vector3d& mean_sensor_g, const Eigen::Matrix3d& gain,
                             const Eigen::Matrix3d& to_machine, const Eigen::Vector3d& direction,
                             const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

}  // namespace eical::drivers
