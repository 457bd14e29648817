#pragma once
// Errors between the axes, as deviations of the relative position for a set-point p:
// squareness (the second axis of a pair leans towards the first: x −= ε_xy·y for xy,
// positive when the angle between the axes is larger than 90°) and straightness (axis i
// bends along `direction` by bow·(1 − u²), u = −1..1 over its span). Each term belongs to
// the axis whose motion causes it — the part (table or head) that moves that axis carries it.
#include "sim/scenario.hpp"

#include <Eigen/Core>

namespace eical::sim {

// Deviation caused by the motion of `axis` at set-point p (mm).
Eigen::Vector3d geometric_deviation_mm(const MachineErrors& e, int axis, const Eigen::Vector3d& p_mm) noexcept;
bool has_geometric_errors(const MachineErrors& e) noexcept;

}  // namespace eical::sim
