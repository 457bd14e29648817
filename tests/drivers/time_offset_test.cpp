// The time offset between a commanded and a measured acceleration (drivers/import/
// time_offset) on a structure that rings: a chirp like Klipper's drives a head that is
// rigid plus two lightly damped modes, each drawn per seed (25–80 Hz, ζ 0.01–0.05, modal
// gain 0.05–0.25, as the klipper-like regime draws them). A plain correlation follows the
// modes' phase: 14–356 µs off on these seeds, 7 of 12 beyond 100 µs. With the structure's
// minimum-phase response taken out (structure_phase.hpp) every seed must lie within 100 µs
// (an eighth of a sample; GCC's build gave at most 52 µs, clang's 74 µs), the rigid head within 20 µs, and the gain
// keep the mounting's sign. The printed error over u shows how far u covers it: the response's estimate leaves a bias
// of some tens of µs that the jackknife does not see (issue 34, open).
#include "drivers/import/time_offset.hpp"
#include "sim/sensor/pt2.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eical::drivers {
namespace {

constexpr double kSweepFs_hz = 800.0;
constexpr int kSweepOversample = 8;
constexpr double kSweepF0_hz = 5.0, kSweepF1_hz = 133.0, kSweepHzPerS = 4.0;  // 32 s of sweep
constexpr double kSweepAccelPerHz = 75.0;                                     // mm/s² per Hz, as Klipper's older test
constexpr double kSweepLead_s = 2.0, kSweepTail_s = 2.0;

double sweep_accel(double t_s) {
  if (t_s < 0.0 || t_s > (kSweepF1_hz - kSweepF0_hz) / kSweepHzPerS) return 0.0;
  const double f = kSweepF0_hz + kSweepHzPerS * t_s;
  return kSweepAccelPerHz * f * std::sin(2.0 * std::numbers::pi * (kSweepF0_hz * t_s + 0.5 * kSweepHzPerS * t_s * t_s));
}

struct HeadMode {
  double f_hz, zeta, gain;
};

struct RingingCase {
  MeasuredSeries measured;
  ReferenceSignal reference;
  double offset_s = 0.0;
};

// The head's acceleration (rigid + modes) along x, read by a sensor whose x points along
// −x when `flipped`, with white noise; the recorder's clock runs `offset_s` ahead.
RingingCase ringing_head(const std::vector<HeadMode>& modes, bool flipped, std::uint64_t seed) {
  RingingCase c;
  const double hf = 1.0 / (kSweepFs_hz * kSweepOversample), duration_s = (kSweepF1_hz - kSweepF0_hz) / kSweepHzPerS;
  // An offset off the measurement's grid: whole fine steps plus a part of one.
  c.offset_s = 1234.0 + 37.0 * hf;
  std::vector<sim::Pt2> filters;
  for (const HeadMode& m : modes) filters.emplace_back(m.f_hz, m.zeta, hf);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 20.0);  // mm/s² rms: a MEMS chip's noise at 800 Hz
  c.measured.fs_hz = kSweepFs_hz;
  c.measured.t0_s = c.offset_s - kSweepLead_s;
  const auto fine_steps = static_cast<long>(std::lround((duration_s + kSweepLead_s + kSweepTail_s) / hf));
  for (long m = 0; m <= fine_steps; ++m) {
    const double t_setpoint_s = -kSweepLead_s + static_cast<double>(m) * hf;
    const double x = sweep_accel(t_setpoint_s);
    double head = x;
    for (std::size_t i = 0; i < modes.size(); ++i) head += modes[i].gain * filters[i].step(x);
    if (m % kSweepOversample != 0) continue;
    const long n = m / kSweepOversample;
    if (n % 997 == 500) continue;  // a lost frame now and then
    c.measured.grid_index.push_back(n);
    c.measured.values.emplace_back((flipped ? -head : head) + noise(rng), noise(rng), noise(rng));
  }
  c.reference.t_begin_s = 0.0, c.reference.t_end_s = duration_s;
  c.reference.moving = Eigen::Vector3d(1.0, 0.0, 0.0);
  c.reference.accel = [](double t) { return Eigen::Vector3d(sweep_accel(t), 0.0, 0.0); };
  return c;
}

TEST(TimeOffset, RigidHeadIsAlignedToAFractionOfASample) {
  const RingingCase c = ringing_head({}, false, 1);
  const OffsetEstimate e = estimate_offset(c.measured, c.reference, kSweepOversample);
  const double err_s = e.offset_s - c.offset_s;
  std::printf("rigid: error %.1f us, u %.1f us, explained %.1f %%\n", err_s * 1e6, e.u_s * 1e6, 100.0 * e.explained);
  EXPECT_LT(std::abs(err_s), 20e-6);
  EXPECT_LT(e.u_s, 0.1 / kSweepFs_hz);
  EXPECT_GT(e.gain(0, 0), 0.0);
  EXPECT_GT(e.explained, 0.9);
}

TEST(TimeOffset, RingingHeadIsAlignedWithItsResponseTakenOut) {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    std::mt19937_64 rng(seed * 7919);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto u = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng); };
    const double f1 = u(25.0, 65.0), f2 = u(f1 + 8.0, 80.0);
    const std::vector<HeadMode> modes = {{f1, u(0.01, 0.05), u(0.05, 0.25)}, {f2, u(0.01, 0.05), u(0.05, 0.25)}};
    const bool flipped = seed % 2 == 0;
    const RingingCase c = ringing_head(modes, flipped, seed);
    const OffsetEstimate e = estimate_offset(c.measured, c.reference, kSweepOversample);
    const double err_s = e.offset_s - c.offset_s;
    std::printf(
        "seed %2llu: modes %.1f Hz (zeta %.3f, gain %.2f), %.1f Hz (zeta %.3f, gain %.2f): error %7.1f us, u "
        "%5.1f us (%+.1f u), structure peak %.1f x, gain %+.3f\n",
        static_cast<unsigned long long>(seed), modes[0].f_hz, modes[0].zeta, modes[0].gain, modes[1].f_hz,
        modes[1].zeta, modes[1].gain, err_s * 1e6, e.u_s * 1e6, err_s / e.u_s, e.structure_peak, e.gain(0, 0));
    EXPECT_LT(std::abs(err_s), 100e-6) << "seed " << seed;
    EXPECT_EQ(e.gain(0, 0) < 0.0, flipped) << "seed " << seed << ": the mounting's sign is lost";
  }
}

}  // namespace
}  // namespace eical::drivers
