// Gravity and the commanded motion against a capture's stated scale and axes map
// (drivers/import/mounting_check): each wrong scale or map named with its fix.
#include "drivers/import/mounting_check.hpp"
#include "sim/sensor/axes_map.hpp"

#include <gtest/gtest.h>

namespace eical::drivers {
namespace {

constexpr double kGPerMmS2 = 1.0 / 9806.65;

// What a sensor mounted by `true_map` (sensor → machine) reads: gravity (+1 g up) times
// `scale`, and the response to commanded acceleration along `direction`.
struct Capture {
  Eigen::Vector3d mean_g;
  Eigen::Matrix3d gain;
};
Capture capture(const std::string& true_map, double scale, const Eigen::Vector3d& direction) {
  const Eigen::Matrix3d to_machine = sim::axes_map_matrix(true_map, "");
  const Eigen::Matrix3d to_sensor = to_machine.transpose();  // a signed permutation: its inverse
  Capture c;
  c.mean_g = scale * to_sensor * Eigen::Vector3d::UnitZ();
  c.gain = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a)
    if (direction[a] != 0.0) c.gain.col(a) = scale * kGPerMmS2 * to_sensor.col(a);
  return c;
}

TEST(MountingCheck, AStatedMountingThatFitsPasses) {
  const Capture c = capture("-y,x,z", 1.02, Eigen::Vector3d::UnitX());
  const MountingCheck m =
      check_mounting(c.mean_g, c.gain, sim::axes_map_matrix("-y,x,z", ""), Eigen::Vector3d::UnitX());
  EXPECT_TRUE(m.consistent);
  EXPECT_TRUE(m.findings.empty());
  EXPECT_NEAR(m.gravity_g, 1.02, 1e-12);
  EXPECT_FALSE(m.scale_fix);
}

TEST(MountingCheck, AScaleWrongByAFactorIsNamedWithItsFix) {
  // LIS2DW counts converted with ADXL345 constants: about 8 g at rest.
  const Capture c = capture("x,y,z", 8.03, Eigen::Vector3d::UnitY());
  const MountingCheck m = check_mounting(c.mean_g, c.gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitY());
  EXPECT_FALSE(m.consistent);
  ASSERT_TRUE(m.scale_fix);
  EXPECT_NEAR(*m.scale_fix, 1.0 / 8.03, 1e-9);
  ASSERT_EQ(m.findings.size(), 1u);
  EXPECT_NE(m.findings[0].find("--accel-scale 0.1245"), std::string::npos) << m.findings[0];
}

TEST(MountingCheck, AxesTurnedBy90DegreesAreNamedWithTheMapThatFits) {
  // The sensor's x lies along machine y, its y along −x: the file's columns as Klipper wrote
  // them, stated as x,y,z.
  const Capture c = capture("-y,x,z", 1.0, Eigen::Vector3d::UnitX());
  const MountingCheck m = check_mounting(c.mean_g, c.gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  EXPECT_FALSE(m.consistent);
  EXPECT_EQ(m.fitting_map, "-y,x,z");
  ASSERT_EQ(m.findings.size(), 1u);
  EXPECT_NE(m.findings[0].find("--mounting -y,x,z"), std::string::npos) << m.findings[0];
}

// Gravity fits and the motion shows along machine y: the likelier cause, the test run
// along y, is named before a sensor turned about the vertical.
TEST(MountingCheck, AMotionAlongAnotherAxisNamesThatAxisFirst) {
  const Capture c = capture("x,y,z", 1.0, Eigen::Vector3d::UnitY());
  Eigen::Matrix3d gain = Eigen::Matrix3d::Zero();
  gain.col(0) = c.gain.col(1);  // imported as a test along x
  const MountingCheck m = check_mounting(c.mean_g, gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  EXPECT_FALSE(m.consistent);
  ASSERT_EQ(m.findings.size(), 1u);
  EXPECT_NE(m.findings[0].find("the test ran along y (fix: --axis y)"), std::string::npos) << m.findings[0];
}

TEST(MountingCheck, AFlippedVerticalAxisIsNamed) {
  // The sensor turned over about x (its y and z reversed): gravity shows z, and a
  // right-handed map then fixes y.
  const Capture c = capture("x,-y,-z", 1.0, Eigen::Vector3d::UnitX());
  const MountingCheck m = check_mounting(c.mean_g, c.gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  EXPECT_FALSE(m.consistent);
  EXPECT_EQ(m.fitting_map, "x,-y,-z");
}

TEST(MountingCheck, BothWrongAtOnceAreBothNamed) {
  const Capture c = capture("y,-x,z", 7.7, Eigen::Vector3d::UnitY());
  const MountingCheck m = check_mounting(c.mean_g, c.gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitY());
  EXPECT_FALSE(m.consistent);
  EXPECT_EQ(m.findings.size(), 2u);
  EXPECT_EQ(m.fitting_map, "y,-x,z");
  EXPECT_NEAR(*m.scale_fix, 1.0 / 7.7, 1e-9);
}

TEST(MountingCheck, ACaptureWithoutGravityIsNotJudgedByIt) {
  const Capture c = capture("x,y,z", 1.0, Eigen::Vector3d::UnitX());
  const MountingCheck m =
      check_mounting(Eigen::Vector3d(0.01, 0.0, 0.02), c.gain, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  EXPECT_TRUE(m.consistent);
  ASSERT_EQ(m.findings.size(), 1u);
  EXPECT_NE(m.findings[0].find("not checked"), std::string::npos);
}

TEST(MountingCheck, ABeltTestAlongADiagonalFitsItsStatedMounting) {
  const Eigen::Vector3d d = Eigen::Vector3d(1.0, -1.0, 0.0).normalized();
  Capture c = capture("x,y,z", 1.0, Eigen::Vector3d::UnitX());
  // The regression on two collinear columns (x = d/√2·r, y = −d/√2·r) through the Gram
  // matrix's pseudo-inverse: the response to d split as k·d·vᵀ, v = (1, −1, 0)/√2.
  c.gain = kGPerMmS2 * d * d.transpose();
  const MountingCheck m = check_mounting(c.mean_g, c.gain, Eigen::Matrix3d::Identity(), d);
  EXPECT_TRUE(m.consistent) << (m.findings.empty() ? "" : m.findings[0]);
}

}  // namespace
}  // namespace eical::drivers
