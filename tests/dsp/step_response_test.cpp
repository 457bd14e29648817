#include "dsp/eval/step_response.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eical::dsp::eval {
namespace {

constexpr double kStepFs = 2000.0;

// Appends a rest of `rest_s` at `at_mm`, then a raised-cosine move to `to_mm` over `move_s`.
void move(std::vector<double>& cmd, double to_mm, double move_s, double rest_s) {
  const double from = cmd.empty() ? 0.0 : cmd.back();
  for (int i = 0; i < static_cast<int>(rest_s * kStepFs); ++i) cmd.push_back(from);
  const int n = static_cast<int>(move_s * kStepFs);
  for (int i = 1; i <= n; ++i) cmd.push_back(from + (to_mm - from) * 0.5 * (1 - std::cos(std::numbers::pi * i / n)));
}

TEST(StepResponse, OvershootSettlingAndEndErrorOfADampedOscillation) {
  std::vector<double> cmd;
  move(cmd, 1.0, 0.2, 0.3);
  move(cmd, 0.0, 0.2, 0.5);
  move(cmd, 1.0, 0.2, 0.5);
  for (int i = 0; i < static_cast<int>(0.5 * kStepFs); ++i) cmd.push_back(1.0);
  // After each arrival: end error +2 µm and a decaying 25 Hz ringing of 3 µm, τ = 40 ms.
  const double amp_um = 3.0, tau_s = 0.04, f_hz = 25.0, end_um = 2.0;
  std::vector<double> meas(cmd.size());
  double since = 1e9, dir = 1.0;
  for (std::size_t i = 0; i < cmd.size(); ++i) {
    const bool moving = i > 0 && cmd[i] != cmd[i - 1];
    if (moving) since = -1.0 / kStepFs, dir = cmd[i] > cmd[i - 1] ? 1.0 : -1.0;
    since += 1.0 / kStepFs;
    const double ring =
        since >= 0 && !moving ? amp_um * std::exp(-since / tau_s) * std::cos(2 * std::numbers::pi * f_hz * since) : 0.0;
    meas[i] = cmd[i] + (end_um + dir * ring) * 1e-3;
  }
  StepOptions opt;
  opt.settle_band_um = 0.5;
  const auto r = evaluate_steps(cmd, meas, kStepFs, opt);
  ASSERT_EQ(r.moves.size(), 3u);
  EXPECT_NEAR(r.end_position_error_um, end_um, 1e-3);
  // Overshoot beyond the target in the direction of motion: end error + first ring peak
  // for moves up, the first ring peak − end error for the move down.
  EXPECT_NEAR(r.moves[0].overshoot_um, end_um + amp_um, 0.05);
  EXPECT_NEAR(r.moves[1].overshoot_um, amp_um - end_um, 0.05);
  // The envelope leaves the 0.5 µm band at τ·ln(3/0.5); the last excursion is within half
  // a ringing period before that.
  const double envelope_s = tau_s * std::log(amp_um / opt.settle_band_um);
  EXPECT_LE(r.settling_s, envelope_s + 1.0 / kStepFs);
  EXPECT_GE(r.settling_s, envelope_s - 0.5 / f_hz);
  EXPECT_LT(r.scatter_um, 1e-6);
}

TEST(StepResponse, ScatterIsThePooledStandardDeviationOfRepeats) {
  std::vector<double> cmd;
  for (int k = 0; k < 4; ++k) {
    move(cmd, 0.5, 0.1, 0.3);
    move(cmd, 0.0, 0.1, 0.3);
  }
  for (int i = 0; i < static_cast<int>(0.3 * kStepFs); ++i) cmd.push_back(0.0);
  // End errors at 0.5 mm alternate +1/−1 µm around 0 (std with n−1: sqrt(4/3) µm); at 0 mm exact.
  std::vector<double> meas(cmd.size());
  int arrivals = 0;
  double err_um = 0.0;
  for (std::size_t i = 0; i < cmd.size(); ++i) {
    if (i > 0 && cmd[i] == 0.5 && cmd[i - 1] != 0.5) err_um = (arrivals++ % 2 == 0) ? 1.0 : -1.0;
    meas[i] = cmd[i] + (cmd[i] == 0.5 ? err_um * 1e-3 : 0.0);
  }
  const auto r = evaluate_steps(cmd, meas, kStepFs);
  ASSERT_EQ(r.moves.size(), 8u);
  // Pooled over the two groups: ss = 4 (up group), dof = 3 + 3.
  EXPECT_NEAR(r.scatter_um, std::sqrt(4.0 / 6.0), 1e-9);
}

TEST(StepResponse, SmallestStepResolvedUnderStickSlip) {
  // Steps of 100, 50, 20, 10, 5, 2, 1 µm; the axis sticks on anything below 4 µm.
  std::vector<double> cmd;
  double at = 0.0;
  for (double s_um : {100.0, 50.0, 20.0, 10.0, 5.0, 2.0, 1.0}) {
    at += s_um * 1e-3;
    move(cmd, at, 0.05, 0.3);
  }
  for (int i = 0; i < static_cast<int>(0.3 * kStepFs); ++i) cmd.push_back(at);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1e-3);
  std::vector<double> meas(cmd.size());
  double actual = 0.0;
  for (std::size_t i = 0; i < cmd.size(); ++i) {
    if (std::abs(cmd[i] - actual) >= 4e-3) actual = cmd[i];  // moves only once the error exceeds 4 µm
    meas[i] = actual + noise(rng);
  }
  const auto r = evaluate_steps(cmd, meas, kStepFs);
  ASSERT_EQ(r.moves.size(), 7u);
  EXPECT_NEAR(r.noise_um, 0.1, 0.03);
  EXPECT_NEAR(r.smallest_step_resolved_um, 5.0, 1e-9);
}

TEST(StepResponse, BadInputIsRefused) {
  EXPECT_THROW((void)evaluate_steps({0, 0}, {0}, kStepFs), InputError);
  EXPECT_THROW((void)evaluate_steps(std::vector<double>(1000, 0.0), std::vector<double>(1000, 0.0), kStepFs),
               InputError);
  std::vector<double> cmd;
  move(cmd, 1.0, 0.1, 0.3);
  for (int i = 0; i < 600; ++i) cmd.push_back(1.0);
  auto meas = cmd;
  meas[100] = std::nan("");
  EXPECT_THROW((void)evaluate_steps(cmd, meas, kStepFs), InputError);
}

}  // namespace
}  // namespace eical::dsp::eval
