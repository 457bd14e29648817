#include "dsp/comp/lincomp.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eical::dsp::comp {
namespace {

// Why piecewise_linear refuses a curve with these options ("" when it does not).
std::string refusal(const ErrorCurve& curve, const LinCompOptions& options) {
  try {
    (void)piecewise_linear(curve, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

ErrorCurve sample_curve(double travel_mm = 500.0) {
  // A LIDA-like curve: a slow bow, a 37 mm wave and a little noise, every 1 mm.
  ErrorCurve c;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.05);
  for (int i = 0; i <= static_cast<int>(travel_mm); ++i) {
    const double x = i;
    c.pos_mm.push_back(x);
    c.error_um.push_back(2.0 * std::sin(std::numbers::pi * x / travel_mm) +
                         0.6 * std::sin(2 * std::numbers::pi * x / 37.0) + n(rng));
  }
  return c;
}

// Independent brute force: the correction at x from the grid formula directly (bracket
// by floor division; the travel ends are points too), compared at every curve point.
double brute_force_residual(const ErrorCurve& c, double first, double A) {
  auto err_at = [&](double x) {  // the curve is sampled every 1 mm from 0: direct index
    const double fx = std::floor(x);
    const auto i = static_cast<std::size_t>(fx);
    if (i + 1 >= c.pos_mm.size()) return c.error_um.back();
    return c.error_um[i] + (x - fx) * (c.error_um[i + 1] - c.error_um[i]);
  };
  const double end = c.pos_mm.back();
  const int last = static_cast<int>(std::floor((end - first) / A + 1e-9));
  double worst = 0.0;
  for (std::size_t i = 0; i < c.pos_mm.size(); ++i) {
    const double x = c.pos_mm[i];
    double corr;
    const double k = std::floor((x - first) / A);
    const double x0 = c.pos_mm.front(), last_p = first + last * A;
    if (x <= first)
      corr = first > x0 ? err_at(x0) + (x - x0) / (first - x0) * (err_at(first) - err_at(x0)) : err_at(first);
    else if (k >= last)
      corr =
          end > last_p ? err_at(last_p) + (x - last_p) / (end - last_p) * (err_at(end) - err_at(last_p)) : err_at(end);
    else {
      const double a = first + k * A, b = a + A;
      corr = err_at(a) + (x - a) / A * (err_at(b) - err_at(a));
    }
    worst = std::max(worst, std::abs(c.error_um[i] - corr));
  }
  return worst;
}

TEST(LinComp, WorstShiftMatchesABruteForceSearch) {
  const ErrorCurve c = sample_curve();
  for (double A : {50.0, 100.0}) {
    LinCompOptions o;
    o.spacing_mm = A;
    o.period_error_um = 0.4;  // LIDA 400: ±1 % of a 20 µm signal period, as a magnitude
    const LinCompResult r = piecewise_linear(c, o);
    double worst = 0.0, worst_shift = 0.0;
    for (int s = 0; s < static_cast<int>(A); ++s) {
      const double res = brute_force_residual(c, s, A);
      if (res > worst) worst = res, worst_shift = s;
    }
    EXPECT_NEAR(r.max_residual_um, worst, 1e-9) << "A = " << A;
    EXPECT_DOUBLE_EQ(r.worst_shift_mm, worst_shift);
    EXPECT_NEAR(r.total_um, worst + 0.4, 1e-9);
    EXPECT_GE(r.max_residual_um, r.residual_unshifted_um);
    EXPECT_EQ(r.residual_by_shift_um.size(), static_cast<std::size_t>(A));
  }
}

TEST(LinComp, TableRemovesTheErrorAtItsPointsAndALinearErrorEverywhere) {
  ErrorCurve c;
  for (int i = 0; i <= 300; ++i) c.pos_mm.push_back(i), c.error_um.push_back(0.01 * i - 1.0);  // 10 µm/m scale error
  const LinCompResult r = piecewise_linear(c, {.spacing_mm = 50.0, .shift_step_mm = 1.0, .period_error_um = 0.0});
  EXPECT_LT(r.max_residual_um, 1e-12);
  ASSERT_EQ(r.table.pos_mm.size(), 7u);  // 0, 50, ..., 300
  EXPECT_DOUBLE_EQ(r.table.deviation_um[2], 0.0);
}

TEST(LinComp, BadInputIsRefusedWithTheReason) {
  ErrorCurve c = sample_curve(100.0);
  EXPECT_NE(refusal(c, {.spacing_mm = 150.0}).find("larger than the travel"), std::string::npos);
  ErrorCurve dup = c;
  dup.pos_mm[5] = dup.pos_mm[4];
  EXPECT_NE(refusal(dup, {}).find("duplicate"), std::string::npos);
  ErrorCurve back = c;
  back.pos_mm[5] = 2.0;
  EXPECT_NE(refusal(back, {}).find("must increase"), std::string::npos);
  ErrorCurve nan = c;
  nan.error_um[7] = std::nan("");
  EXPECT_NE(refusal(nan, {}).find("point 8"), std::string::npos);
}

// Found by fuzzing (fuzz/corpus/curve_csv/regression-*): a curve over 3.6 km passed every
// bound one at a time and took minutes under the sanitizers; a curve no machine axis can
// have is refused at once, and so is a table recomputed at more shifts than a second's work.
TEST(LinComp, CurvesNoMachineHasAndUnboundedWorkAreRefused) {
  const ErrorCurve km{{5.0, 100.0, 3640388.0}, {1.0, 2.0, 4.0}};
  EXPECT_NE(refusal(km, {}).find("of any machine axis"), std::string::npos) << refusal(km, {});
  const ErrorCurve long_axis{{0.0, 50000.0}, {0.0, 10.0}};  // 50 m: a gantry mill's axis
  EXPECT_EQ(refusal(long_axis, {}), "");
  EXPECT_NE(refusal(long_axis, {.spacing_mm = 10.0, .shift_step_mm = 0.001}).find("table evaluations"),
            std::string::npos);
}

}  // namespace
}  // namespace eical::dsp::comp
