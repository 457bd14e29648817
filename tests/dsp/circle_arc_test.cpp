// Partial-arc circular test (ISO 230-4 with an arc below 360°) on synthetic paths with
// known radius errors: evaluated over the arc only, about the programmed centre, both
// directions combined for H; and the segment finder that picks the arcs from the set-point.
#include "dsp/eval/circle_arc.hpp"
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_segments.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

namespace eical::dsp::eval {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A recording of one sweep: ramp-in (outside the arc), the arc, ramp-out; the radius at
// each angle comes from `radius_error_um(theta_deg)`; M102 marks at the arc's ends.
struct Recording {
  std::vector<Eigen::Vector2d> cmd, pos;
  std::vector<std::int64_t> idx, marks;
};

void sweep(Recording& r, const Eigen::Vector2d& centre, double radius_mm, double from_deg, double arc_deg, bool ccw,
           const std::function<double(double)>& radius_error_um, int samples = 2200) {
  const double ramp_deg = 20.0, sign = ccw ? 1.0 : -1.0;
  const double start = ccw ? from_deg - ramp_deg : from_deg + arc_deg + ramp_deg;
  const int total = samples + 2 * samples * static_cast<int>(ramp_deg) / static_cast<int>(arc_deg);
  const double step = sign * (arc_deg + 2 * ramp_deg) / total;
  bool was_inside = false;
  std::int64_t last_inside = -1;
  for (int k = 0; k <= total; ++k) {
    const double th = start + step * k;
    const bool inside = th >= from_deg - 1e-9 && th <= from_deg + arc_deg + 1e-9;
    // Outside the arc the path is 50 µm off: the evaluation must not see it.
    const double err_um = inside ? radius_error_um(th) : 50.0;
    const Eigen::Vector2d u(std::cos(th * kDeg), std::sin(th * kDeg));
    const std::int64_t i = r.idx.empty() ? 0 : r.idx.back() + 1;
    if (inside && !was_inside) r.marks.push_back(i);            // M102 where the arc begins
    if (!inside && was_inside) r.marks.push_back(last_inside);  // and where it ends
    if (inside) last_inside = i;
    was_inside = inside;
    r.idx.push_back(i);
    r.cmd.push_back(centre + radius_mm * u);
    r.pos.push_back(centre + (radius_mm + err_um * 1e-3) * u);
  }
  for (int k = 0; k < 500; ++k) {  // rest at the reversal
    r.idx.push_back(r.idx.back() + 1);
    r.cmd.push_back(r.cmd.back());
    r.pos.push_back(r.pos.back());
  }
}

CircleInput input_for(const Recording& r, const Eigen::Vector2d& centre, double radius_mm, const std::string& direction,
                      double arc_deg) {
  CircleInput in;
  in.pos_mm = r.pos;
  in.sample_index = r.idx;
  in.center_mm = centre;
  in.radius_mm = radius_mm;
  in.direction = direction;
  for (const auto& s : find_circle_segments(r.cmd, r.idx, r.marks, centre, arc_deg))
    if (s.direction == direction) in.segments.emplace_back(s.begin_index, s.end_index);
  return in;
}

const Eigen::Vector2d kCentre(5.0, -3.0);
constexpr double kRadius = 10.0, kArc = 220.0, kFrom = -20.0;

TEST(CircleArc, SegmentFinderKeepsTheArcsAndDropsTheReversal) {
  Recording r;
  sweep(r, kCentre, kRadius, kFrom, kArc, true, [](double) { return 0.0; });
  sweep(r, kCentre, kRadius, kFrom, kArc, false, [](double) { return 0.0; });
  ASSERT_EQ(r.marks.size(), 4u);
  const auto segs = find_circle_segments(r.cmd, r.idx, r.marks, kCentre, kArc);
  ASSERT_EQ(segs.size(), 2u);  // marks 2–3 (ramp-out, rest, ramp-in) is no arc
  EXPECT_EQ(segs[0].direction, "ccw");
  EXPECT_EQ(segs[1].direction, "cw");
  EXPECT_NEAR(segs[0].sweep_deg, kArc, 0.5);
  EXPECT_NEAR(segs[1].sweep_deg, -kArc, 0.5);
  // A program that claims another arc finds nothing to evaluate.
  EXPECT_TRUE(find_circle_segments(r.cmd, r.idx, r.marks, kCentre, 180.0).empty());
}

TEST(CircleArc, KnownRadiusErrorIsMeasuredOverTheArcOnly) {
  const double radius_error_um = 3.0;
  Recording r;
  sweep(r, kCentre, kRadius, kFrom, kArc, true, [&](double) { return radius_error_um; });
  const CircleResult c = evaluate_arc(input_for(r, kCentre, kRadius, "ccw", kArc), kArc);
  EXPECT_EQ(c.revolutions, 1);
  EXPECT_DOUBLE_EQ(c.arc_deg, kArc);
  EXPECT_NEAR(c.radius_mean_deviation_um, radius_error_um, 1e-6);
  EXPECT_NEAR(c.radial_deviation_F_max_um, radius_error_um, 1e-6);
  EXPECT_NEAR(c.radial_deviation_F_min_um, radius_error_um, 1e-6);
  EXPECT_NEAR(c.circular_deviation_G_um, 0.0, 1e-6);
  EXPECT_FALSE(c.circular_hysteresis_H_um.has_value());
  // The trace covers the arc, not the ramps (where the path is 50 µm off).
  for (double a : c.trace.angle_deg) {
    const double rel = std::fmod(a - kFrom + 360.0, 360.0);
    EXPECT_LE(rel, kArc + 0.2) << a;
  }
}

TEST(CircleArc, FormErrorAndHysteresisFromBothDirections) {
  // ccw: δ + h/2 + A·cos 2θ, cw: δ − h/2 + A·cos 2θ (the same form, shifted by the reversal).
  const double delta_um = -2.0, h_um = 1.5, lobe_um = 0.8;
  Recording r;
  sweep(r, kCentre, kRadius, kFrom, kArc, true,
        [&](double th) { return delta_um + h_um / 2 + lobe_um * std::cos(2 * th * kDeg); });
  sweep(r, kCentre, kRadius, kFrom, kArc, false,
        [&](double th) { return delta_um - h_um / 2 + lobe_um * std::cos(2 * th * kDeg); });
  const CircleResult a = evaluate_arc(input_for(r, kCentre, kRadius, "ccw", kArc), kArc);
  const CircleResult b = evaluate_arc(input_for(r, kCentre, kRadius, "cw", kArc), kArc);
  const CircleResult c = combine(a, b);
  EXPECT_EQ(c.direction, "both");
  EXPECT_EQ(c.revolutions, 2);
  // 2θ runs over −40° … 400°: cos 2θ reaches ±1 on the arc.
  EXPECT_NEAR(c.radial_deviation_F_max_um, delta_um + h_um / 2 + lobe_um, 1e-3);
  EXPECT_NEAR(c.radial_deviation_F_min_um, delta_um - h_um / 2 - lobe_um, 1e-3);
  EXPECT_NEAR(c.circular_deviation_G_um, h_um + 2 * lobe_um, 2e-3);
  ASSERT_TRUE(c.circular_hysteresis_H_um.has_value());
  // 1° bins: the lobe changes by up to 2A·sin(1°)·… within a bin, equally in both directions.
  EXPECT_NEAR(*c.circular_hysteresis_H_um, h_um, 0.02);
  // Mean of the lobe over the arc, computed from its definition.
  double lobe_mean = 0.0;
  for (double v : a.trace.radius_deviation_um) lobe_mean += v - (delta_um + h_um / 2);
  lobe_mean /= static_cast<double>(a.trace.radius_deviation_um.size());
  EXPECT_NEAR(c.radius_mean_deviation_um, delta_um + lobe_mean, 0.01);
}

TEST(CircleArc, CentreIsTheProgrammedOneSoACentreOffsetShows) {
  // The path is a perfect circle about a centre 2 µm off in +a. About the programmed
  // centre the radius deviation is ≈ e·cos θ; over −20° … 200° that spans +e … −e.
  const double e_um = 2.0;
  Recording r;
  sweep(r, kCentre, kRadius, kFrom, kArc, true, [](double) { return 0.0; });
  for (auto& p : r.pos) p.x() += e_um * 1e-3;
  const CircleResult c = evaluate_arc(input_for(r, kCentre, kRadius, "ccw", kArc), kArc);
  EXPECT_NEAR(c.radial_deviation_F_max_um, e_um, 1e-3);
  EXPECT_NEAR(c.radial_deviation_F_min_um, -e_um, 1e-3);
  EXPECT_NEAR(c.circular_deviation_G_um, 2 * e_um, 2e-3);
  ASSERT_EQ(c.centers_mm.size(), 1u);
  EXPECT_EQ(c.centers_mm[0], kCentre);
}

TEST(CircleArc, BadInputNamesTheCause) {
  CircleInput in;
  in.radius_mm = 10.0;
  try {
    (void)evaluate_arc(in, 220.0);
    FAIL() << "no arc accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no evaluated arc"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)evaluate_arc(in, 0.0), InputError);
  EXPECT_THROW((void)find_circle_segments({Eigen::Vector2d::Zero()}, {}, {}, Eigen::Vector2d::Zero(), 220.0),
               InputError);
}

}  // namespace
}  // namespace eical::dsp::eval
