#include "dsp/eval/path_deviation.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace eical::dsp::eval {
namespace {

constexpr double kFs = 1000.0;

TEST(PathDeviation, StraightLineSplitsNormalOffsetAndLag) {
  // 20 mm/s along x; the measurement sits 3 µm to the left (+y) and lags 0.5 ms (10 µm).
  std::vector<Eigen::Vector3d> cmd, meas;
  for (int i = 0; i < 2000; ++i) {
    const double t = i / kFs;
    cmd.emplace_back(20.0 * t, 0.0, 0.0);
    meas.emplace_back(20.0 * (t - 0.0005), 0.003, 0.0);
  }
  const auto d = path_deviation(cmd, meas, kFs);
  ASSERT_GT(d.sample.size(), 1900u);
  for (std::size_t k = 10; k < d.sample.size(); ++k) {
    EXPECT_NEAR(d.normal_um[k], 3.0, 1e-6);
    EXPECT_NEAR(d.tangential_um[k], -10.0, 1e-6);
  }
  EXPECT_NEAR(d.contour_error_max_um, 3.0, 1e-6);
}

TEST(PathDeviation, SelfCrossingFigureEightMatchesTheRightPass) {
  // Lemniscate x = sin t, y = sin t cos t (scaled); the measured path is pushed outward
  // along the local normal by 2 µm. At the crossing both passes are at the same point:
  // a global nearest-point search could pick the wrong pass, the windowed one must not.
  std::vector<Eigen::Vector3d> cmd, meas;
  const int n = 8000;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    const Eigen::Vector3d p(10 * std::sin(t), 10 * std::sin(t) * std::cos(t), 0);
    const Eigen::Vector3d v(10 * std::cos(t), 10 * std::cos(2 * t), 0);
    const Eigen::Vector3d left = Eigen::Vector3d(-v.y(), v.x(), 0).normalized();
    cmd.push_back(p);
    meas.push_back(p + 0.002 * left);
  }
  const auto d = path_deviation(cmd, meas, kFs);
  for (std::size_t k = 0; k < d.sample.size(); ++k) ASSERT_NEAR(d.normal_um[k], 2.0, 0.01) << "sample " << d.sample[k];
  EXPECT_NEAR(d.tangential_rms_um, 0.0, 0.01);
}

TEST(PathDeviation, RestAndBadInput) {
  std::vector<Eigen::Vector3d> still(100, Eigen::Vector3d::Zero());
  EXPECT_THROW((void)path_deviation(still, still, kFs), InputError);
  std::vector<Eigen::Vector3d> a(10, Eigen::Vector3d::Zero()), b(9, Eigen::Vector3d::Zero());
  EXPECT_THROW((void)path_deviation(a, b, kFs), InputError);
}

}  // namespace
}  // namespace eical::dsp::eval
