// Damping that grows with |a|, where the vibration both sensors share shows it
// (dsp/model/damping_band_regression.hpp): a head that carries x, y and z (as on the independent
// simulator's HERMLE) runs the thesis' circle under a 100 Hz tone and broadband vibration.
// With k = 1.4 on the head the test names the head and k within ±35 % (the
// first-order model reads 15–20 % low here, inside the 20 % it adds to the uncertainty); with k = 0 it names
// nothing; with one sensor it says why it cannot test.
#include "dsp/model/damping_band_regression.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

namespace eical {
namespace {

sim::Scenario head_carries_all_axes(double zeta_per_g, std::uint64_t seed) {
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 5, "ccw", seed);
  sc.meta.machine.table_axes = {};
  sc.meta.machine.head_axes = {"x", "y", "z"};
  sim::Tone tone;
  tone.freq_hz = 100.0, tone.amp_mg = Eigen::Vector3d(4.3, 1.7, 1.3), tone.phase_deg = 77.0;
  sc.common_vibration.tones = {tone};
  sc.common_vibration.broadband_rms_mg = Eigen::Vector3d(0.6, 0.6, 0.7);
  sc.truth[1].zeta_per_g = zeta_per_g;
  return sc;
}

dsp::model::DampingBandFinding test_on(const sim::Scenario& sc) {
  return dsp::model::damping_band_test(dsp::model::build_residuals(sim::simulate(sc)));
}

// The finding at seeds 1 and 2 of the head's k, each printed.
std::vector<dsp::model::DampingBandFinding> at_two_seeds(double zeta_per_g) {
  std::vector<dsp::model::DampingBandFinding> out;
  for (std::uint64_t seed : {1, 2}) {
    out.push_back(test_on(head_carries_all_axes(zeta_per_g, seed)));
    std::printf("seed %llu: %s%s\n", static_cast<unsigned long long>(seed), out.back().evidence.c_str(),
                out.back().why.c_str());
  }
  return out;
}

TEST(DampingBand, NamesTheHeadAndItsCoefficientWhereTheSharedVibrationProbesIt) {
  for (const dsp::model::DampingBandFinding& f : at_two_seeds(1.4)) {
    ASSERT_TRUE(f.valid) << f.why;
    EXPECT_TRUE(f.found);
    EXPECT_EQ(f.sensor, 1);
    EXPECT_NEAR(f.zeta_per_g, 1.4, 0.35 * 1.4);
    EXPECT_GT(f.sigma_zeta_per_g, 0.0);
  }
}

TEST(DampingBand, FindsNothingWhenTheDampingDoesNotGrow) {
  for (const dsp::model::DampingBandFinding& f : at_two_seeds(0.0)) {
    ASSERT_TRUE(f.valid) << f.why;
    EXPECT_FALSE(f.found);
    EXPECT_LT(f.bic_drop[1], 0.0);
  }
}

TEST(DampingBand, SaysWhyItCannotTestWithOneSensorOrNoVibration) {
  sim::Scenario one = head_carries_all_axes(1.4, 1);
  one.meta.sensor_present[0] = false;
  const dsp::model::DampingBandFinding a = test_on(one);
  EXPECT_FALSE(a.valid);
  EXPECT_NE(a.why.find("both sensors"), std::string::npos) << a.why;

  sim::Scenario quiet = head_carries_all_axes(1.4, 1);
  quiet.common_vibration = {};
  const dsp::model::DampingBandFinding b = test_on(quiet);
  EXPECT_FALSE(b.valid);
  EXPECT_NE(b.why.find("vibration"), std::string::npos) << b.why;
}

}  // namespace
}  // namespace eical
