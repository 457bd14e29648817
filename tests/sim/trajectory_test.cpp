// The interpolator against the sample runs' truth (their NC timing is known to 1e-9 s)
// and against its own limits.
#include "sim/nc/trajectory.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/gcode/parser.hpp"
#include "sim/nc/sampled_set_point.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace eical::sim::nc {
namespace {

Trajectory circle_trajectory(int repeats = 5) {
  dsp::Program p;
  p.kind = eical::dsp::ProgramKind::circle;
  p.repeats = repeats;
  return interpolate_gcode(gcode::circle_program(p), "circle", MachineLimits{});
}

TEST(Trajectory, CircleTimingMatchesTheSampleRunsTruth) {
  const Trajectory tr = circle_trajectory();
  // truth.toml of baseline-0011: moves_s = [[0.5, 8.851539632]], triggers 101 at 0.4, 102 at
  // 0.9058586319, 2.413823106, ..., 8.445681001, 103 at 9.251539632. The generator of those
  // runs moved on the exact R = 10 mm circle; the G-code text rounds the start point to
  // 0.1 µm (7.0711), so the NC's radius is 10.0000455 mm and each revolution is 0.29 µm
  // (6.9 µs) longer: allow 6 revolutions of that.
  const double tol = 5e-5;
  ASSERT_EQ(tr.moves().size(), 1u);
  EXPECT_NEAR(tr.moves()[0].t0_s, 0.5, 1e-12);
  EXPECT_NEAR(tr.moves()[0].t0_s + tr.moves()[0].profile.duration_s(), 8.851539632, tol);
  const std::vector<double> t102 = {0.9058586319, 2.413823106, 3.921787579, 5.429752053, 6.937716527, 8.445681001};
  std::vector<double> got;
  for (const auto& t : tr.triggers())
    if (t.code == 102) got.push_back(t.t_s);
  ASSERT_EQ(got.size(), t102.size());
  for (std::size_t k = 0; k < got.size(); ++k) EXPECT_NEAR(got[k], t102[k], tol);
  EXPECT_NEAR(tr.triggers().front().t_s, 0.4, 1e-12);
  EXPECT_NEAR(tr.triggers().back().t_s, 9.251539632, tol);
  EXPECT_NEAR(tr.duration_s(), 9.351539632, tol);
}

TEST(Trajectory, CircleRunsOnTheRadiusAtFeedWithinTheLimits) {
  const Trajectory tr = circle_trajectory(2);
  const double feed = 2500.0 / 60.0;
  double max_acc = 0.0, max_jerk = 0.0;
  MotionState prev = tr.at(0.0);
  const double h = 1e-4;
  for (double t = h; t < tr.duration_s(); t += h) {
    const MotionState s = tr.at(t);
    ASSERT_NEAR(std::hypot(s.pos_mm.x(), s.pos_mm.y()), std::hypot(7.0711, 7.0711), 1e-9) << t;
    // Velocity and acceleration are the derivatives of position (central differences).
    const MotionState a = tr.at(t - h / 2), b = tr.at(t + h / 2);
    ASSERT_LT((s.vel_mm_s - (b.pos_mm - a.pos_mm) / h).norm(), 1e-3) << t;
    ASSERT_LT((s.acc_mm_s2 - (b.vel_mm_s - a.vel_mm_s) / h).norm(), 50000.0 * h) << t;  // jerk steps: j·h
    // Path (tangential) acceleration within a_max; jerk of the path speed within j_max.
    const double tangential = s.acc_mm_s2.dot(s.vel_mm_s.normalized());
    if (s.vel_mm_s.norm() > 1e-9) max_acc = std::max(max_acc, std::abs(tangential));
    max_jerk = std::max(max_jerk, std::abs(s.vel_mm_s.norm() - prev.vel_mm_s.norm()) / h);
    prev = s;
  }
  EXPECT_LE(max_acc, 2000.0 * (1 + 1e-9));
  EXPECT_NEAR(tr.at(3.0).vel_mm_s.norm(), feed, 1e-9);
  EXPECT_EQ(tr.at(0.45).vel_mm_s.norm(), 0.0);                    // at rest before the move
  EXPECT_EQ(tr.at(tr.duration_s() - 0.05).vel_mm_s.norm(), 0.0);  // and after
}

TEST(Trajectory, ExactStopStepsReachTheirTargetsAndRest) {
  dsp::Program p;
  p.kind = eical::dsp::ProgramKind::step;
  p.targets_mm = {0.0, 50.0};
  p.feed_mm_min = 3250.0;
  p.runs = 2;
  p.dwell_s = 0.5;
  const Trajectory tr = interpolate(gcode::parse(gcode::step_program(p)), Eigen::Vector3d::Zero(), MachineLimits{});
  ASSERT_EQ(tr.moves().size(), 4u);
  int arrivals = 0;
  for (const auto& trig : tr.triggers()) {
    if (trig.code != 102) continue;
    const MotionState s = tr.at(trig.t_s + 0.25);  // mid-dwell
    EXPECT_EQ(s.vel_mm_s.norm(), 0.0);
    EXPECT_NEAR(s.pos_mm.x(), arrivals % 2 == 0 ? 50.0 : 0.0, 1e-12);
    ++arrivals;
  }
  EXPECT_EQ(arrivals, 4);
}

TEST(Trajectory, PerAxisLimitsHoldOnADiagonalMove) {
  // A 30° move: x takes cos 30° of the path speed. x may do 1500 mm/min, 0.5 m/s² and
  // 10 m/s³ — below the path limits — so the whole move is slowed for x's sake.
  MachineLimits lim;
  lim.axis_v_mm_min[0] = 1500.0;
  lim.axis_a_mm_s2[0] = 500.0;
  lim.axis_j_mm_s3[0] = 10000.0;
  const Trajectory tr =
      interpolate_gcode("G90 G21 G17 G61\nG0 X0 Y0\nG4 P0.1\nG1 X43.3013 Y25 F6000\nG4 P0.1\n", "diag", lim);
  double vx = 0.0, ax = 0.0, jx = 0.0, vy = 0.0;
  const double h = 1e-4;
  for (double t = h; t < tr.duration_s(); t += h) {
    const MotionState s = tr.at(t), p = tr.at(t - h);
    vx = std::max(vx, std::abs(s.vel_mm_s.x()) * 60.0);
    vy = std::max(vy, std::abs(s.vel_mm_s.y()) * 60.0);
    ax = std::max(ax, std::abs(s.acc_mm_s2.x()));
    jx = std::max(jx, std::abs(s.acc_mm_s2.x() - p.acc_mm_s2.x()) / h);
  }
  EXPECT_LE(vx, 1500.0 * (1 + 1e-6));
  EXPECT_GT(vx, 1500.0 * 0.999);                                  // the limit is reached, not undercut
  EXPECT_NEAR(vy, 1500.0 * std::tan(std::numbers::pi / 6), 1.0);  // y follows the path direction
  EXPECT_LE(ax, 500.0 * (1 + 1e-6));
  EXPECT_LE(jx, 10000.0 * 1.01);
  EXPECT_NEAR(tr.at(tr.duration_s()).pos_mm.x(), 43.3013, 1e-9);
}

TEST(SampledSetPoint, SplineThroughServoSamplesRecoversMotion) {
  // Another NC's 1 kHz samples of eical's own circle: the spline reproduces position,
  // velocity and acceleration between the samples.
  const Trajectory tr = circle_trajectory(1);
  std::vector<Eigen::Vector3d> samples;
  for (double t = 0.0; t <= tr.duration_s(); t += 1e-3) samples.push_back(tr.at(t).pos_mm);
  const SampledSetPoint sp(samples, 1000.0, tr.triggers());
  double pos = 0, vel = 0, acc = 0;
  for (double t = 0.6; t < 2.0; t += 0.000737) {
    const MotionState a = tr.at(t), b = sp.at(t);
    pos = std::max(pos, (a.pos_mm - b.pos_mm).norm());
    vel = std::max(vel, (a.vel_mm_s - b.vel_mm_s).norm());
    acc = std::max(acc, (a.acc_mm_s2 - b.acc_mm_s2).norm());
  }
  EXPECT_LT(pos, 1e-6);  // mm
  EXPECT_LT(vel, 1e-3);  // mm/s
  EXPECT_LT(acc, 30.0);  // mm/s² (jerk 50 m/s³ over half a servo period)
  ASSERT_EQ(sp.move_spans_s().size(), 1u);
  EXPECT_NEAR(sp.move_spans_s()[0].first, tr.moves()[0].t0_s, 2e-3);
  EXPECT_EQ(sp.triggers().size(), tr.triggers().size());
}

}  // namespace
}  // namespace eical::sim::nc
