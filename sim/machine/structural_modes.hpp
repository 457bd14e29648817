#pragma once
// Structural modes between the drive and the measured point (machine.resonance): each
// mode's displacement m along its unit direction d follows
//   m'' + 2ζω m' + ω² m = −gain · (d · a_drive),
// the same PT2 integrator as the drive-excited vibration (sim/machine/vibration): Pt2 has
// DC gain 1, so its input is −gain·(d·a)/ω², held over each step at the step's mean.
#include "sim/scenario.hpp"
#include "sim/sensor/pt2.hpp"

#include <Eigen/Core>

#include <vector>

namespace eical::sim {

class StructuralModesResponse {
 public:
  StructuralModesResponse(const std::vector<StructuralMode>& modes, double step_s);
  // Displacement (mm, machine axes) of the measured point against the drive for the
  // commanded acceleration (mm/s²) at this sample.
  Eigen::Vector3d step(const Eigen::Vector3d& cmd_acc_mm_s2) noexcept;
  [[nodiscard]] bool on() const noexcept { return !modes_.empty(); }

 private:
  struct Mode {
    Eigen::Vector3d direction;
    double input_per_accel;  // −gain/ω²
    Pt2 pt2;
  };
  std::vector<Mode> modes_;
  Eigen::Vector3d prev_ = Eigen::Vector3d::Zero();
};

}  // namespace eical::sim
