// Full-circle evaluation (ISO 230-4) on synthetic paths: the least-squares circle far from
// the origin, and the figures-only evaluation the uncertainty's draws use.
#include "dsp/eval/circle.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/index_span.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>

namespace eical::dsp::eval {
namespace {

// Two revolutions ccw about `centre` with a two-lobe radius error of `lobe_um` and M102
// marks at each revolution's start.
CircleInput two_revolutions(const Eigen::Vector2d& centre, double radius_mm, double lobe_um) {
  CircleInput in;
  in.center_mm = centre, in.radius_mm = radius_mm;
  constexpr int kPerRev = 3600;
  for (int k = 0; k <= 2 * kPerRev; ++k) {
    const double th = 2.0 * std::numbers::pi * k / kPerRev;
    const double r = radius_mm + lobe_um * 1e-3 * std::cos(2.0 * th);
    in.sample_index.push_back(k);
    in.pos_mm.push_back(centre + r * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
  in.segment_marks = {0, kPerRev, 2 * kPerRev};
  return in;
}

TEST(CircleFitTest, FindsCentreAndRadiusFarFromTheOrigin) {
  // A table 600 mm out, a 150 mm circle: the fit's normal equations are centred first.
  const Eigen::Vector2d centre(612.345, -287.5);
  std::vector<Eigen::Vector2d> pts;
  for (int k = 0; k < 5000; ++k) {
    const double th = 2.0 * std::numbers::pi * k / 5000.0;
    pts.push_back(centre + 150.002 * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
  const CircleFit fit = fit_circle(pts);
  EXPECT_NEAR((fit.center - centre).norm(), 0.0, 1e-9) << "centre " << fit.center.transpose();
  EXPECT_NEAR(fit.radius, 150.002, 1e-9);
}

TEST(CircleEvaluationTest, FiguresOnlyEqualTheTracedEvaluationAndKeepNoTrace) {
  CircleInput in = two_revolutions({250.0, 40.0}, 150.0, 3.0);
  const CircleResult traced = evaluate_circle(in);
  in.keep_trace = false;
  const CircleResult bare = evaluate_circle(in);
  // The two-lobe error of ±3 µm about the fitted circle: G = 6 µm.
  EXPECT_NEAR(traced.circular_deviation_G_um, 6.0, 1e-3);
  EXPECT_EQ(traced.trace.radius_deviation_um.size(), traced.points);
  EXPECT_TRUE(bare.trace.radius_deviation_um.empty() && bare.trace.angle_deg.empty() && bare.trace.direction.empty());
  EXPECT_EQ(bare.points, traced.points);
  EXPECT_EQ(bare.revolutions, 2);
  EXPECT_DOUBLE_EQ(bare.circular_deviation_G_um, traced.circular_deviation_G_um);
  EXPECT_DOUBLE_EQ(bare.radius_mean_deviation_um, traced.radius_mean_deviation_um);
  EXPECT_DOUBLE_EQ(bare.radial_deviation_F_max_um, traced.radial_deviation_F_max_um);
  EXPECT_EQ(bare.deviation_sum_by_deg, traced.deviation_sum_by_deg);
}

TEST(CircleEvaluationTest, RevolutionsAreCutByIndexAndOutOfOrderIndicesAreRefused) {
  // Each revolution holds the samples from its mark up to the next one, however the trace
  // around it is cut.
  CircleInput in = two_revolutions({0.0, 0.0}, 10.0, 1.0);
  const CircleResult whole = evaluate_circle(in);
  EXPECT_EQ(whole.points, 7200u);  // 3600 a revolution, the last sample (the end mark) in none
  const IndexSpan second = index_span(in.sample_index, 3600, 7200);
  EXPECT_EQ(second.begin, 3600u);
  EXPECT_EQ(second.size(), 3600u);
  EXPECT_EQ(index_span(in.sample_index, -50, 0).size(), 0u);        // before the trace
  EXPECT_EQ(index_span(in.sample_index, 9000, 9500).begin, 7201u);  // after it
  EXPECT_EQ(index_span(in.sample_index, 500, 400).size(), 0u);      // an empty stretch
  std::swap(in.sample_index[10], in.sample_index[11]);
  try {
    (void)evaluate_circle(in);
    FAIL() << "indices out of order were evaluated";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sample indices do not ascend"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eical::dsp::eval
