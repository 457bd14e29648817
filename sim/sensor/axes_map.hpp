#pragma once
// Axis maps in Klipper's axes_map notation ("x,-z,y": the first named axis, with its sign,
// is what becomes X, the second Y, the third Z). As a matrix M (rows X, Y, Z; ±1 in the
// column of the named axis) it maps the named frame onto the result: v_out = M · v_in.
// For a sensor's columns that is run.toml's to_machine (rows machine axes, columns sensor
// axes); in the simulator a wrong mounting is to_machine_true = M · to_machine_stated.
#include <Eigen/Core>

#include <string>
#include <string_view>

namespace eical::sim {

// Throws InputError naming `what` (if not empty) unless `map` names each of x, y, z once.
Eigen::Matrix3d axes_map_matrix(std::string_view map, const std::string& what);

// The map's text for a signed permutation matrix ("" when the matrix is not one).
std::string axes_map_text(const Eigen::Matrix3d& m);

}  // namespace eical::sim
