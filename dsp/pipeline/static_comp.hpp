#pragma once
// Static compensation of one triplex sensor (v1): ADC counts → volts → g with the
// data-sheet scale k1, minus the data-sheet bias, then the inverse of the k2/k3
// nonlinearity to first order (6-17), then sensor axes → machine axes. The rest-window
// bias of the pipeline removes what the data-sheet bias misses (and gravity).
#include "dsp/core/run_meta.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace eical::dsp {

struct StaticComp {
  Eigen::Matrix3d to_machine = Eigen::Matrix3d::Identity();
  Eigen::Vector3d volts_per_count_over_k1 = Eigen::Vector3d::Ones();  // lsb / k1, g per count
  Eigen::Vector3d bias_g = Eigen::Vector3d::Zero();
  Eigen::Vector3d k2 = Eigen::Vector3d::Zero(), k3 = Eigen::Vector3d::Zero();
  double offset_counts = 0.0;
  double g_mps2 = 9.81;

  StaticComp() = default;
  StaticComp(const SensorSpec& spec, const Acquisition& acq, const Site& site);

  // Specific force in machine axes, m/s².
  [[nodiscard]] Eigen::Vector3d apply(const std::int32_t counts[3]) const noexcept {
    Eigen::Vector3d a;
    for (int i = 0; i < 3; ++i) {
      const double g = (static_cast<double>(counts[i]) - offset_counts) * volts_per_count_over_k1[i] - bias_g[i];
      a[i] = g - k2[i] * g * g - k3[i] * g * g * g;  // (6-17)
    }
    return to_machine * a * g_mps2;
  }
};

}  // namespace eical::dsp
