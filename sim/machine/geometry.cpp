#include "sim/machine/geometry.hpp"

namespace eical::sim {

Eigen::Vector3d geometric_deviation_mm(const MachineErrors& e, int axis, const Eigen::Vector3d& p_mm) noexcept {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  // Pairs xy, yz, zx: the second axis (y, z, x) carries the squareness of pair k.
  const int pair = (axis + 2) % 3;  // y → xy (0), z → yz (1), x → zx (2)
  const int first = pair;           // x for xy, y for yz, z for zx
  if (e.squareness_urad[pair] != 0.0) d[first] -= e.squareness_urad[pair] * 1e-6 * p_mm[axis];
  const Straightness& s = e.straightness[axis];
  if (s.direction >= 0 && s.direction != axis && s.bow_um != 0.0) {
    const double mid = 0.5 * (s.span_mm[0] + s.span_mm[1]), half = 0.5 * (s.span_mm[1] - s.span_mm[0]);
    const double u = half > 0.0 ? (p_mm[axis] - mid) / half : 0.0;
    d[s.direction] += s.bow_um * 1e-3 * (1.0 - u * u);
  }
  return d;
}

bool has_geometric_errors(const MachineErrors& e) noexcept {
  for (int i = 0; i < 3; ++i)
    if (e.squareness_urad[i] != 0.0 || (e.straightness[i].direction >= 0 && e.straightness[i].bow_um != 0.0))
      return true;
  return false;
}

}  // namespace eical::sim
