#pragma once
// The deviation of all three channels at every standstill an M102 marks (a target reached,
// a corner): the mean of measured − set-point over the second half of the dwell, as ISO
// 230-2 takes it for the moving axis (dsp/analysis positioning_deviations); the channels of
// the axes that stand still carry the straightness and squareness seen along the move.
#include "dsp/pipeline/pipeline.hpp"

#include <Eigen/Core>

#include <vector>

namespace eical::dsp::comp {

struct Standstill {
  Eigen::Vector3d cmd_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d dev_um = Eigen::Vector3d::Zero();
  Eigen::Vector3i approach = Eigen::Vector3i::Zero();  // +1 / −1: direction each axis last moved in; 0 never moved
  // The smoother's posterior σ of the position over the same samples (Measurement::sigma_um):
  // what the integration between the supports leaves, shared by repeated runs.
  Eigen::Vector3d sigma_um = Eigen::Vector3d::Zero();
};

std::vector<Standstill> standstills(const Measurement& m);

}  // namespace eical::dsp::comp
