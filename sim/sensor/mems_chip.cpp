#include "sim/sensor/mems_chip.hpp"

#include "dsp/core/error.hpp"

#include <cmath>

namespace eical::sim {

const std::vector<MemsChip>& mems_chips() {
  static const std::vector<MemsChip> chips = {
      {"adxl345", 3200.0, 13, 16.0, 290.0 / std::sqrt(2.0), 1600.0, true},
      {"lis2dw", 1600.0, 14, 16.0, 90.0 / std::sqrt(2.0), 800.0, true},
      {"mpu6050", 1000.0, 16, 16.0, 400.0 / std::sqrt(2.0), 260.0, false},
  };
  return chips;
}

const MemsChip& mems_chip(std::string_view name) {
  std::string known;
  for (const MemsChip& c : mems_chips()) {
    if (c.name == name) return c;
    known += (known.empty() ? "" : ", ") + c.name;
  }
  throw dsp::InputError("unknown MEMS chip '" + std::string(name) + "' (known: " + known + ")");
}

dsp::SensorSpec mems_sensor_spec(const MemsChip& chip, double odr_hz) {
  dsp::SensorSpec s;
  s.model = chip.name;
  s.k1_v_per_g = Eigen::Vector3d::Ones();
  s.k2_g_per_g2 = Eigen::Vector3d::Zero();
  s.k3_g_per_g3 = Eigen::Vector3d::Zero();
  s.bias_g = Eigen::Vector3d::Zero();
  s.tc_k1_ppm_per_c = 0.0;
  s.tc_bias_ug_per_c = 0.0;
  s.f0_hz = chip.bandwidth_at(odr_hz);
  s.zeta = 0.707;
  s.noise_ug_per_rthz = chip.noise_ug_per_rthz;
  s.temp_ref_c = 20.0;
  return s;
}

}  // namespace eical::sim
