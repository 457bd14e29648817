#include "dsp/eval/rectangle.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace eical::dsp::eval {
namespace {

constexpr double kRectangleFs = 1000.0;

// A 20 × 10 mm rectangle at 10 mm/s with 0.1 s stops; the machine's Y axis is tilted by
// `square_urad` (moving +y also moves x by −α·y), a corner error is added at (20, 10) and
// side 1 (the x move) is bowed by `bow_um` in y.
void make(double square_urad, double bow_um, std::vector<Eigen::Vector2d>& cmd, std::vector<Eigen::Vector2d>& meas) {
  const std::vector<Eigen::Vector2d> corners = {{0, 0}, {20, 0}, {20, 10}, {0, 10}, {0, 0}};
  auto stop = [&](const Eigen::Vector2d& p) {
    for (int i = 0; i < 100; ++i) cmd.push_back(p);
  };
  stop(corners[0]);
  for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
    const Eigen::Vector2d d = corners[k + 1] - corners[k];
    const int n = static_cast<int>(d.norm() / 10.0 * kRectangleFs);
    for (int i = 1; i <= n; ++i) cmd.push_back(corners[k] + d * (static_cast<double>(i) / n));
    stop(corners[k + 1]);
  }
  for (const auto& c : cmd) {
    Eigen::Vector2d m = c;
    m.x() -= square_urad * 1e-6 * c.y();
    if (c.y() == 0.0) m.y() += bow_um * 1e-3 * (1.0 - std::pow((c.x() - 10.0) / 10.0, 2));
    if ((c - Eigen::Vector2d(20, 10)).norm() < 1e-12) m += Eigen::Vector2d(0.004, -0.002);
    meas.push_back(m);
  }
}

TEST(Rectangle, CornerErrorsSquarenessAndStraightness) {
  std::vector<Eigen::Vector2d> cmd, meas;
  make(50.0, 2.0, cmd, meas);
  const auto r = evaluate_rectangle(cmd, meas, kRectangleFs);
  ASSERT_EQ(r.corners_mm.size(), 5u);
  ASSERT_EQ(r.sides.size(), 4u);
  // Corner (20, 10): the injected error plus the squareness shift −α·y = −0.5 µm in x.
  EXPECT_NEAR(r.corner_errors_um[2].x(), 4.0 - 0.5, 1e-6);
  EXPECT_NEAR(r.corner_errors_um[2].y(), -2.0, 1e-6);
  // Side 2 runs +y and leans towards −x: turned counter-clockwise by α, so the angle
  // between +X and +Y exceeds 90° by α (positive squareness, results.md convention).
  EXPECT_NEAR(r.sides[1].direction_error_urad, 50.0, 0.5);
  EXPECT_NEAR(r.corner_angle_error_urad[0], 50.0, 0.5);
  // Bow 2·(1 − q²) µm, q = (x − 10)/10, over the middle 80 % (|q| < 0.8): from 2 µm at
  // the middle to 0.72 µm at the ends; the LSQ line is level by symmetry → 1.28 µm.
  EXPECT_NEAR(r.sides[0].straightness_um, 2.0 * 0.64, 0.02);
  EXPECT_NEAR(r.sides[2].straightness_um, 0.0, 1e-6);
}

TEST(Rectangle, TooFewStopsIsAnError) {
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i < 1000; ++i) line.emplace_back(i * 0.01, 0.0);
  EXPECT_THROW((void)evaluate_rectangle(line, line, kRectangleFs), InputError);
}

}  // namespace
}  // namespace eical::dsp::eval
