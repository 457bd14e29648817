#include "dsp/comp/fourier.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

namespace eical::dsp::comp {
namespace {

struct Harmonic {
  int f;
  double a_arcsec, phase_deg;
};
const std::vector<Harmonic> kTruth = {
    {1, 3.0, 20.0}, {3, 1.5, -70.0}, {7, 0.8, 130.0}, {12, 1.0, 45.0}, {24, 0.5, -10.0}};

double truth(double x_deg) {
  double s = 0.0;
  for (const auto& h : kTruth) s += h.a_arcsec * std::sin((h.f * x_deg + h.phase_deg) * std::numbers::pi / 180.0);
  return s;
}

// A 12-face polygon, 6 interleaved series started 5° apart; every series' summed division
// errors refer to its own start (so it carries −F(start)); noise 0.1″.
std::vector<AngleSeries> interleaved(bool with_sweep) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<AngleSeries> out;
  for (int m = 0; m < 6; ++m) {
    AngleSeries s;
    s.name = "series" + std::to_string(m);
    const double start = 5.0 * m;
    for (int k = 0; k < 12; ++k) {
      const double x = start + 30.0 * k;
      s.angle_deg.push_back(x);
      s.deviation_arcsec.push_back(truth(x) - truth(start) + noise(rng));
    }
    out.push_back(s);
  }
  if (with_sweep) {
    AngleSeries s;
    s.name = "sweep";
    for (double x = 0.0; x <= 30.0; x += 0.25) {
      s.angle_deg.push_back(x);
      s.deviation_arcsec.push_back(truth(x) - truth(0.0) + noise(rng));
    }
    out.push_back(s);
  }
  return out;
}

std::set<int> significant(const FourierResult& r) {
  std::set<int> s;
  for (const auto& t : r.terms)
    if (t.significant) s.insert(t.frequency);
  return s;
}

TEST(Fourier, CentringLosesFrequenciesAtMultiplesOfN) {
  const FourierResult r = fourier_calibration(interleaved(false), {});
  EXPECT_EQ(r.points_per_series, 12);
  EXPECT_EQ(significant(r), (std::set<int>{1, 3, 7}));
  EXPECT_EQ(r.lost_frequencies, (std::vector<int>{12, 24}));
  for (const auto& t : r.terms) {
    if (!t.significant) continue;
    for (const auto& h : kTruth)
      if (h.f == t.frequency) {
        EXPECT_NEAR(t.amplitude_arcsec, h.a_arcsec, 4 * t.u_amplitude_arcsec + 0.02) << "f = " << h.f;
        EXPECT_NEAR(std::remainder(t.phase_deg - h.phase_deg, 360.0), 0.0, 5.0) << "f = " << h.f;
      }
  }
}

TEST(Fourier, SweepOverOneIntervalRecoversThem) {
  FourierOptions o;
  o.sweep_series = "sweep";
  o.positioning_bound_arcsec = 2.0;
  const FourierResult r = fourier_calibration(interleaved(true), o);
  EXPECT_EQ(significant(r), (std::set<int>{1, 3, 7, 12, 24}));
  for (const auto& t : r.terms)
    if (t.from_sweep && t.significant) {
      const double a = t.frequency == 12 ? 1.0 : 0.5;
      EXPECT_NEAR(t.amplitude_arcsec, a, 0.05) << t.frequency;
    }
  // GUM (10)-(11): U = 2·√(u_x² + u_p²), u_p = a/√3 (the seed: a = 2″ → 1.16″).
  EXPECT_NEAR(r.u_p_arcsec, 2.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(r.expanded_U_arcsec, 2.0 * std::hypot(r.u_x_arcsec, r.u_p_arcsec), 1e-12);
  EXPECT_GT(r.u_x_arcsec, 0.0);
  // The calibration function reproduces the truth up to a constant at unseen angles.
  const double c = truth(0.0) - r.evaluate(0.0);
  for (double x = 1.0; x < 360.0; x += 17.3) EXPECT_NEAR(r.evaluate(x) + c, truth(x), 0.2) << x;
}

TEST(Fourier, F2QuantileMatchesItsTail) {
  // P(F(2, ν) > q) = (1 + 2q/ν)^(−ν/2) must equal α at the quantile.
  for (double nu : {5.0, 30.0, 300.0})
    for (double a : {0.05, 0.01}) EXPECT_NEAR(std::pow(1 + 2 * f2_quantile(a, nu) / nu, -nu / 2), a, 1e-12);
}

TEST(Fourier, BadInput) {
  auto s = interleaved(false);
  s[2].angle_deg.pop_back();
  s[2].deviation_arcsec.pop_back();
  EXPECT_THROW((void)fourier_calibration(s, {}), InputError);
  s = interleaved(false);
  s[1].deviation_arcsec[3] = std::nan("");
  EXPECT_THROW((void)fourier_calibration(s, {}), InputError);
  FourierOptions o;
  o.sweep_series = "missing";
  EXPECT_THROW((void)fourier_calibration(interleaved(false), o), InputError);
}

// Issue 19: a series named as the sweep that is not one (here an interleaved series: its
// positions lie on the polygon grid) used to give an amplitude of 9.9e12.
TEST(Fourier, ASweepThatIsNotASweepIsAClearError) {
  auto series = interleaved(false);
  FourierOptions o;
  o.sweep_series = "series3";
  try {
    (void)fourier_calibration(series, o);
    FAIL() << "a grid series was taken for a sweep";
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("series 'series3' is not a sweep: its 12 positions fall on 1 phase(s) of the 30"),
        std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eical::dsp::comp
