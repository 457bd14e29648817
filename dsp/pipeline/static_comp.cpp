#include "dsp/pipeline/static_comp.hpp"

#include <Eigen/LU>

namespace eical::dsp {

StaticComp::StaticComp(const SensorSpec& spec, const Acquisition& acq, const Site& site, const StaticCalibration& cal,
                       const StaticCompOptions& options)
    : g_per_count(acq.adc_lsb_volt / spec.k1_v_per_g.array()),
      offset_counts(static_cast<double>(acq.adc_offset_counts)),
      bias_g(spec.bias_g),
      tc_k1_per_c(options.temperature ? spec.tc_k1_ppm_per_c * 1e-6 : 0.0),
      tc_bias_g_per_c(options.temperature ? spec.tc_bias_ug_per_c * 1e-6 : 0.0),
      temp_ref_c(spec.temp_ref_c),
      cross_g_per_g(cal.cross_g_per_g),
      cross2_g_per_g2(cal.cross2_g_per_g2),
      cross_inverse((Eigen::Matrix3d::Identity() + cal.cross_g_per_g).inverse()),
      to_machine_mps2_per_g(spec.to_machine * cal.mounting * site.g_mps2) {
  if (options.nonlinearity) k2_g_per_g2 = spec.k2_g_per_g2, k3_g_per_g3 = spec.k3_g_per_g3;
  iterate = k2_g_per_g2.squaredNorm() > 0.0 || k3_g_per_g3.squaredNorm() > 0.0 || cross_g_per_g.squaredNorm() > 0.0 ||
            cross2_g_per_g2.squaredNorm() > 0.0;
}

Eigen::Vector3d static_model_g(const Eigen::Vector3d& v_g, const SensorSpec& spec, const StaticCalibration& cal) {
  Eigen::Vector3d u;
  for (int i = 0; i < 3; ++i) {
    u[i] = v_g[i] + spec.k2_g_per_g2[i] * v_g[i] * v_g[i] + spec.k3_g_per_g3[i] * v_g[i] * v_g[i] * v_g[i];
    for (int j = 0; j < 3; ++j)
      if (j != i) u[i] += cal.cross_g_per_g(i, j) * v_g[j] + cal.cross2_g_per_g2(i, j) * v_g[i] * v_g[j];
  }
  return u;
}

}  // namespace eical::dsp
