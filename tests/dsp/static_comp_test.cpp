// StaticComp: the inverse of the static model (6-4) with temperature (6-16), nonlinearity
// (6-17), cross terms and mounting (6-18), checked against the forward model.
#include "dsp/pipeline/static_comp.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace eical::dsp {
namespace {

TEST(StaticComp, InvertsTheForwardModelWithTemperatureCrossTermsAndMounting) {
  SensorSpec spec;
  spec.k2_g_per_g2 = {-7e-4, 9e-4, -1.6e-3};
  spec.k3_g_per_g3 = {6e-4, -1e-3, -1.5e-3};
  StaticCalibration cal;
  cal.cross_g_per_g << 0, 2e-3, -1e-3, 1.5e-3, 0, 5e-4, -8e-4, 3e-4, 0;
  cal.cross2_g_per_g2 << 0, 1e-4, -2e-4, 3e-4, 0, 1e-4, 2e-4, -1e-4, 0;
  cal.mounting = Eigen::AngleAxisd(4e-3, Eigen::Vector3d(0.3, -0.2, 1.0).normalized()).toRotationMatrix();
  Acquisition acq;
  acq.adc_lsb_volt = 1e-8, acq.adc_offset_counts = 1234;  // ±3 V within int32
  const Site site;
  const StaticComp comp(spec, acq, site, cal);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> acc(-2.0, 2.0), temp(10.0, 50.0);
  double worst_g = 0.0;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d v(acc(rng), acc(rng), 1.0 + acc(rng) * 0.5);
    const double t_c = temp(rng), dt_c = t_c - spec.temp_ref_c;
    const Eigen::Vector3d u = static_model_g(v, spec, cal);
    std::int32_t counts[3];
    Eigen::Vector3d quantisation_g;
    for (int i = 0; i < 3; ++i) {  // the simulator's ADC: U = k1(T)(u + bias(T)), counts = round(U/lsb) + offset
      const double k1 = spec.k1_v_per_g[i] * (1.0 + spec.tc_k1_ppm_per_c * 1e-6 * dt_c);
      const double volts = k1 * (u[i] + spec.bias_g[i] + spec.tc_bias_ug_per_c * 1e-6 * dt_c);
      counts[i] = static_cast<std::int32_t>(std::llround(volts / acq.adc_lsb_volt)) + 1234;
      quantisation_g[i] = acq.adc_lsb_volt / k1;
    }
    const Eigen::Vector3d a = comp.apply(counts, t_c);
    const Eigen::Vector3d expected = spec.to_machine * cal.mounting * v * site.g_mps2;
    worst_g = std::max(worst_g, (a - expected).cwiseAbs().maxCoeff() / site.g_mps2);
    EXPECT_LT((a - expected).cwiseAbs().maxCoeff() / site.g_mps2, quantisation_g.maxCoeff()) << "sample " << k;
  }
  std::printf("static model inverse over +-2 g, 10..50 C: worst error %.2e g (ADC step %.1e g)\n", worst_g,
              acq.adc_lsb_volt / 1.235);
}

TEST(StaticComp, IterationGoesBeyondTheThesisFirstOrderFormula) {
  // (6-17) a_kor = a − k2 a² − k3 a³ alone misses ≈ 2 k2² at 1 g; the iteration does not.
  SensorSpec spec;
  const StaticCalibration cal;
  const StaticComp comp(spec, Acquisition{}, Site{}, cal);
  const Eigen::Vector3d v(0.5, -0.3, 1.0);
  const Eigen::Vector3d u = static_model_g(v, spec, cal);
  const Eigen::Vector3d first_order =
      u.array() - spec.k2_g_per_g2.array() * u.array().square() - spec.k3_g_per_g3.array() * u.array().cube();
  const Eigen::Vector3d iterated = comp.invert_model(u);
  EXPECT_GT((first_order - v).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((iterated - v).cwiseAbs().maxCoeff(), 1e-11);
}

TEST(StaticComp, OptionsSwitchTemperatureAndNonlinearityOff) {
  SensorSpec spec;
  const StaticComp off(spec, Acquisition{}, Site{}, {}, {.temperature = false, .nonlinearity = false});
  EXPECT_EQ(off.tc_k1_per_c, 0.0);
  EXPECT_EQ(off.tc_bias_g_per_c, 0.0);
  EXPECT_FALSE(off.iterate);
  const Eigen::Vector3d u(0.2, 0.1, 1.0);
  EXPECT_EQ(off.invert_model(u), u);
}

}  // namespace
}  // namespace eical::dsp
