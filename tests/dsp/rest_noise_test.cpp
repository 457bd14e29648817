// The relative acceleration's white noise measured at rest (Allan deviation at τ, median
// of the cluster differences): the density it was made with, at the DAQ's rate and at a
// MEMS sensor's; a knock in a rest window does not move it; too little rest says so.
#include "dsp/pipeline/rest_noise.hpp"
#include "dsp/uncertainty/rest_noise_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace eical::dsp {
namespace {

constexpr double kG = 9.81;

// `seconds` of white noise of two-sided density n_ug (σ = n·√fs per sample, the run
// format's convention) on each axis, into the meter.
void feed(RestNoiseMeter& meter, double fs_hz, double seconds, double n_ug, std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  const double sigma_mps2 = n_ug * 1e-6 * kG * std::sqrt(fs_hz);
  const auto n = static_cast<std::size_t>(seconds * fs_hz);
  for (std::size_t k = 0; k < n; ++k) meter.sample(Eigen::Vector3d(g(rng), g(rng), g(rng)) * sigma_mps2);
}

TEST(RestNoise, MeasuresTheDensityItWasMadeWith) {
  for (const double fs_hz : {10000.0, 3200.0, 400.0}) {
    RestNoiseMeter meter(fs_hz, kG);
    std::mt19937_64 rng(11);
    feed(meter, fs_hz, 2.0, 0.566, rng);
    const RestNoise r = meter.result();
    ASSERT_TRUE(r.measured()) << fs_hz;
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(r.density_ug_rthz[i] / 0.566, 1.0, 3.0 * r.relative_u()) << "fs " << fs_hz << " axis " << i;
    EXPECT_NEAR(r.quiet_s, 2.0, 0.01);
    std::printf("fs %.0f Hz: tau %.1f ms, %zu clusters, density %.3f %.3f %.3f (made 0.566, ±%.0f %%)\n", fs_hz,
                r.tau_s * 1000.0, r.differences, r.density_ug_rthz.x(), r.density_ug_rthz.y(), r.density_ug_rthz.z(),
                100.0 * r.relative_u());
  }
}

TEST(RestNoise, AKnockInARestWindowDoesNotMoveIt) {
  RestNoiseMeter quiet(10000.0, kG), knocked(10000.0, kG);
  std::mt19937_64 a(5), b(5);
  feed(quiet, 10000.0, 1.0, 0.5, a);
  feed(knocked, 10000.0, 0.5, 0.5, b);
  for (int k = 0; k < 200; ++k) knocked.sample(Eigen::Vector3d::Constant(0.05 * std::sin(k * 0.3)));  // 5 mg ringing
  feed(knocked, 10000.0, 0.5, 0.5, b);
  const double q = quiet.result().density_ug_rthz.x(), k = knocked.result().density_ug_rthz.x();
  EXPECT_NEAR(k / q, 1.0, 0.2) << "quiet " << q << ", with a knock " << k;
}

TEST(RestNoise, GapsStartNewClustersAndTooLittleRestIsNotAMeasurement) {
  RestNoiseMeter meter(10000.0, kG);
  std::mt19937_64 rng(3);
  feed(meter, 10000.0, 0.02, 0.5, rng);  // 4 clusters: 3 differences
  meter.gap();
  feed(meter, 10000.0, 0.02, 0.5, rng);
  EXPECT_FALSE(meter.result().measured());
  EXPECT_TRUE(std::isnan(meter.result().density_ug_rthz.x()));
  meter.reset();
  EXPECT_EQ(meter.result().differences, 0u);
}

TEST(RestNoise, ADensityOutsideTheDataSheetsSpreadIsFlagged) {
  RestNoiseMeter meter(10000.0, kG);
  std::mt19937_64 rng(9);
  feed(meter, 10000.0, 2.0, 0.566, rng);
  const RestNoise ok = meter.result();
  EXPECT_FALSE(uncertainty::noise_disagreement(ok, 0.566));
  meter.reset();
  feed(meter, 10000.0, 2.0, 1.2, rng);  // twice the data sheet's
  const auto flag = uncertainty::noise_disagreement(meter.result(), 0.566);
  ASSERT_TRUE(flag);
  EXPECT_EQ(flag->code, FlagCode::noise_density);
  EXPECT_EQ(severity(*flag), FlagSeverity::warning);
  EXPECT_NE(flag->detail.find("above the data sheet's 0.566"), std::string::npos) << flag->detail;
  EXPECT_NE(uncertainty::noise_source_text(ok, 0.566).find("measured at rest"), std::string::npos);
  EXPECT_NE(uncertainty::noise_source_text(RestNoise{}, 0.566).find("from the data sheet"), std::string::npos);
}

}  // namespace
}  // namespace eical::dsp
