#include "sim/machine/structural_modes.hpp"

#include "dsp/core/error.hpp"

#include <numbers>

namespace eical::sim {

StructuralModesResponse::StructuralModesResponse(const std::vector<StructuralMode>& modes, double step_s) {
  for (const StructuralMode& m : modes) {
    if (m.gain == 0.0) continue;
    if (!(m.frequency_hz > 0.0) || !(m.damping_ratio > 0.0) || !(m.direction.norm() > 0.0))
      throw dsp::InputError(
          "machine.resonance: a mode needs a positive frequency, a positive damping ratio and a direction");
    const double w = 2.0 * std::numbers::pi * m.frequency_hz;
    modes_.push_back({m.direction.normalized(), -m.gain / (w * w), Pt2(m.frequency_hz, m.damping_ratio, step_s)});
  }
}

Eigen::Vector3d StructuralModesResponse::step(const Eigen::Vector3d& cmd_acc_mm_s2) noexcept {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  const Eigen::Vector3d mean = 0.5 * (cmd_acc_mm_s2 + prev_);  // the input over the step, second-order accurate
  for (Mode& m : modes_) out += m.direction * m.pt2.step(m.input_per_accel * m.direction.dot(mean));
  prev_ = cmd_acc_mm_s2;
  return out;
}

}  // namespace eical::sim
