// Each ballbar-class diagnostic is injected alone into a synthetic two-direction circular
// test; the fit must recover it (±15 % or ±0.5 µm, the tolerance) and report ≈ 0
// for every diagnostic that was not injected.
#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace eical::dsp::eval {
namespace {

struct Injected {
  double backlash_x_um = 0, backlash_y_um = 0;
  double lateral_x_um = 0;
  double cyclic_x_um = 0, pitch_mm = 5.0;
  double lag_x_ms = 0, lag_y_ms = 0;
  double squareness_urad = 0;
  double scale_x_ppm = 0, scale_y_ppm = 0;
  double straightness_x_um = 0;  // bow of X travel at mid-travel vs the span's ends, seen on y
  double spike_x_um = 0;         // decaying lag after each x reversal (friction holds the axis)
  double noise_um = 0.1;
};

constexpr double kDiagRadiusMm = 10.0, kDiagFeed = 2500.0, kDiagFs = 1000.0;

CirclePass make_pass(int direction, const Injected& in, std::uint64_t seed) {
  CirclePass p;
  p.direction = direction;
  p.fs_hz = kDiagFs;
  const double w = kDiagFeed / 60.0 / kDiagRadiusMm * direction;  // rad/s
  const auto n = static_cast<std::size_t>(5 * 2 * std::numbers::pi / std::abs(w) * kDiagFs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, in.noise_um * 1e-3);
  double last_sx = 0.0, since_rev_s = 1e9;
  // A positive backlash is a play between motor and slide (the slide waits at a reversal
  // until the motor has crossed it); a negative one has no such mechanism and stays a step.
  double slide_x = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kDiagFs;
    const double th = std::numbers::pi / 4 + w * t;
    const Eigen::Vector2d c(kDiagRadiusMm * std::cos(th), kDiagRadiusMm * std::sin(th));
    const Eigen::Vector2d v(-kDiagRadiusMm * w * std::sin(th), kDiagRadiusMm * w * std::cos(th));
    const double sx = v.x() > 0 ? 1.0 : -1.0, sy = v.y() > 0 ? 1.0 : -1.0;
    if (last_sx != 0.0 && sx != last_sx) since_rev_s = 0.0;
    last_sx = sx;
    Eigen::Vector2d e;
    const double b = in.backlash_x_um * 1e-3;
    double lost_x = -b / 2 * sx;
    if (b > 0.0) {
      if (std::isnan(slide_x)) slide_x = c.x() - b / 2 * sx;
      slide_x = std::clamp(slide_x, c.x() - b / 2, c.x() + b / 2);
      lost_x = slide_x - c.x();
    }
    e.x() = in.scale_x_ppm * 1e-6 * c.x() - in.squareness_urad * 1e-6 * c.y() - in.lag_x_ms * 1e-3 * v.x() + lost_x +
            in.lateral_x_um * 1e-3 / 2 * sy +
            in.cyclic_x_um * 1e-3 * std::sin(2 * std::numbers::pi * c.x() / in.pitch_mm + 0.3) -
            in.spike_x_um * 1e-3 * sx * std::exp(-since_rev_s / 0.008);
    e.y() = in.scale_y_ppm * 1e-6 * c.y() - in.lag_y_ms * 1e-3 * v.y() - in.backlash_y_um * 1e-3 / 2 * sy +
            in.straightness_x_um * 1e-3 * (1.0 - (c.x() / kDiagRadiusMm) * (c.x() / kDiagRadiusMm));
    // Integration drift: an offset and a slow quadratic per pass.
    e += Eigen::Vector2d(0.004 + 0.002 * t / 7.5, -0.003 + 0.003 * (t / 7.5) * (t / 7.5));
    e += Eigen::Vector2d(noise(rng), noise(rng));
    p.cmd_mm.push_back(c);
    p.meas_mm.push_back(c + e);
    since_rev_s += 1.0 / kDiagFs;
  }
  return p;
}

CircleDiagnostics run(const Injected& in) {
  DiagnosticsOptions opt;
  opt.radius_mm = kDiagRadiusMm;
  opt.cyclic_pitch_mm = in.pitch_mm;
  return diagnose_circle({make_pass(+1, in, 1), make_pass(-1, in, 2)}, opt);
}

// The tolerance: ±15 % of the truth or ±0.5 µm, whichever is larger.
void expect_near_truth(double reported, double truth, const char* what) {
  EXPECT_NEAR(reported, truth, std::max(0.15 * std::abs(truth), 0.5)) << what;
}

// Everything except `skip` (the injected one) must read ≈ 0.
void expect_others_zero(const CircleDiagnostics& d, const std::string& skip) {
  auto z = [&](const char* name, double v, double tol) {
    if (skip.find(name) == std::string::npos) {
      EXPECT_NEAR(v, 0.0, tol) << name << " (injected: " << skip << ")";
    }
  };
  z("backlash_x", d.backlash_x_um, 0.5);
  z("backlash_y", d.backlash_y_um, 0.5);
  z("lateral_x", d.lateral_play_x_um, 0.5);
  z("cyclic_x", d.cyclic_error_x_um, 0.5);
  z("servo", d.servo_mismatch_ms, 0.012);  // 0.5 µm at 41.7 mm/s
  z("square", d.squareness_urad, 50.0);    // 0.5 µm over R = 10 mm
  z("scale", d.scale_mismatch_ppm, 50.0);
  z("straight_x", d.straightness_x_um, 0.5);
  z("spike_x", d.reversal_spike_x_um, 0.5);
}

TEST(CircleDiagnostics, CleanMachineReadsZero) {
  const auto d = run({});
  expect_others_zero(d, "");
  EXPECT_TRUE(d.servo_and_squareness_separated);
  EXPECT_LT(d.residual_rms_um, 0.3);
}

TEST(CircleDiagnostics, Backlash) {
  Injected in;
  in.backlash_x_um = 6.0;
  in.backlash_y_um = -3.0;
  const auto d = run(in);
  expect_near_truth(d.backlash_x_um, 6.0, "backlash x");
  expect_near_truth(d.backlash_y_um, -3.0, "backlash y");
  expect_others_zero(d, "backlash_x backlash_y");
}

TEST(CircleDiagnostics, LateralPlay) {
  Injected in;
  in.lateral_x_um = 4.0;
  const auto d = run(in);
  expect_near_truth(d.lateral_play_x_um, 4.0, "lateral play x");
  expect_others_zero(d, "lateral_x");
}

TEST(CircleDiagnostics, CyclicError) {
  Injected in;
  in.cyclic_x_um = 2.0;
  const auto d = run(in);
  expect_near_truth(d.cyclic_error_x_um, 2.0, "cyclic x");
  expect_others_zero(d, "cyclic_x");
}

TEST(CircleDiagnostics, ServoMismatchSeparatedFromSquarenessWithBothDirections) {
  Injected in;
  in.lag_x_ms = 1.2;
  in.lag_y_ms = 1.0;
  in.squareness_urad = 80.0;
  const auto d = run(in);
  expect_near_truth(d.servo_mismatch_ms, 0.2, "servo mismatch");
  expect_near_truth(d.squareness_urad, 80.0, "squareness");
  expect_others_zero(d, "servo square");
}

TEST(CircleDiagnostics, ScaleMismatch) {
  Injected in;
  in.scale_x_ppm = 150.0;
  in.scale_y_ppm = -50.0;
  const auto d = run(in);
  expect_near_truth(d.scale_mismatch_ppm, 200.0, "scale mismatch");
  expect_others_zero(d, "scale");
}

TEST(CircleDiagnostics, Straightness) {
  Injected in;
  in.straightness_x_um = 3.0;
  const auto d = run(in);
  expect_near_truth(d.straightness_x_um, 3.0, "straightness x");
  expect_others_zero(d, "straight_x");
}

TEST(CircleDiagnostics, ReversalSpikeOfOneAxisIsFoundOnThatAxis) {
  Injected in;
  in.spike_x_um = 5.0;
  const auto d = run(in);
  expect_near_truth(d.reversal_spike_x_um, 5.0, "spike x");
  EXPECT_NEAR(d.reversal_spike_y_um, 0.0, 0.5);
  expect_others_zero(d, "spike_x");
}

TEST(CircleDiagnostics, OneDirectionSaysItCannotSeparateServoFromSquareness) {
  Injected in;
  in.squareness_urad = 100.0;
  DiagnosticsOptions opt;
  opt.radius_mm = kDiagRadiusMm;
  opt.cyclic_pitch_mm = 5.0;
  const auto d = diagnose_circle({make_pass(+1, in, 3)}, opt);
  EXPECT_FALSE(d.servo_and_squareness_separated);
  ASSERT_FALSE(d.notes.empty());
  expect_near_truth(d.squareness_urad, 100.0, "squareness, one direction, equal lags");
}

TEST(CircleDiagnostics, BadInputIsRefusedWithAReason) {
  DiagnosticsOptions opt;
  EXPECT_THROW((void)diagnose_circle({}, opt), InputError);
  CirclePass p = make_pass(+1, {}, 4);
  p.meas_mm[10].x() = std::nan("");
  try {
    (void)diagnose_circle({p}, opt);
    FAIL() << "NaN accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos);
  }
}

}  // namespace
}  // namespace eical::dsp::eval
