// The diagnostics from a set-point's design (what the uncertainty's draws use: one design,
// some 200 paths) must equal the diagnostics computed from the passes alone, whatever the
// machine, the directions, the pitch search, the rate and the feed; a design of another
// set-point or a non-finite path is refused.
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_diagnostics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace eical::dsp::eval {
namespace {

constexpr double kR = 10.0, kFeed = 2500.0;

struct Machine {
  double backlash_x_mm = 0.004, lag_x_s = 0.0012, lag_y_s = 0.001, squareness = 8e-5, scale_x = 1.5e-4;
  double cyclic_x_mm = 0.002, pitch_mm = 5.0, spike_x_mm = 0.003, noise_mm = 2e-4;
};

// Revolutions at fs_hz of a machine with the errors above (backlash as a step, a decaying
// spike after each x reversal, a slow drift per pass) and white noise.
CirclePass pass_of(int direction, const Machine& m, double fs_hz, std::uint64_t seed, int revolutions = 3) {
  CirclePass p;
  p.direction = direction, p.fs_hz = fs_hz;
  const double w = kFeed / 60.0 / kR * direction;
  const auto n = static_cast<std::size_t>(revolutions * 2 * std::numbers::pi / std::abs(w) * fs_hz);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, m.noise_mm);
  double last_sx = 0.0, since_s = 1e9;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs_hz, th = 0.3 + w * t;
    const Eigen::Vector2d c(kR * std::cos(th), kR * std::sin(th));
    const Eigen::Vector2d v(-kR * w * std::sin(th), kR * w * std::cos(th));
    const double sx = v.x() > 0 ? 1.0 : -1.0;
    if (last_sx != 0.0 && sx != last_sx) since_s = 0.0;
    last_sx = sx;
    Eigen::Vector2d e(m.scale_x * c.x() - m.squareness * c.y() - m.lag_x_s * v.x() - m.backlash_x_mm / 2 * sx +
                          m.cyclic_x_mm * std::sin(2 * std::numbers::pi * c.x() / m.pitch_mm) -
                          m.spike_x_mm * sx * std::exp(-since_s / 0.008),
                      -m.lag_y_s * v.y());
    e += Eigen::Vector2d(0.004 + 0.002 * t, -0.003 + 0.003 * t * t) + Eigen::Vector2d(noise(rng), noise(rng));
    p.cmd_mm.push_back(c), p.meas_mm.push_back(c + e);
    since_s += 1.0 / fs_hz;
  }
  return p;
}

// Every numeric figure of the diagnostics, by name.
struct Figure {
  const char* name;
  double CircleDiagnostics::*value;
};
constexpr Figure kFigures[] = {
    {"backlash x", &CircleDiagnostics::backlash_x_um},
    {"backlash y", &CircleDiagnostics::backlash_y_um},
    {"spike x", &CircleDiagnostics::reversal_spike_x_um},
    {"spike y", &CircleDiagnostics::reversal_spike_y_um},
    {"lateral x", &CircleDiagnostics::lateral_play_x_um},
    {"lateral y", &CircleDiagnostics::lateral_play_y_um},
    {"cyclic x", &CircleDiagnostics::cyclic_error_x_um},
    {"cyclic y", &CircleDiagnostics::cyclic_error_y_um},
    {"cyclic pitch", &CircleDiagnostics::cyclic_pitch_mm},
    {"servo mismatch", &CircleDiagnostics::servo_mismatch_ms},
    {"squareness", &CircleDiagnostics::squareness_urad},
    {"scale mismatch", &CircleDiagnostics::scale_mismatch_ppm},
    {"straightness x", &CircleDiagnostics::straightness_x_um},
    {"straightness y", &CircleDiagnostics::straightness_y_um},
    {"stick-slip", &CircleDiagnostics::stick_slip_um},
    {"vibration", &CircleDiagnostics::vibration_um},
    {"lag x", &CircleDiagnostics::lag_x_ms},
    {"lag y", &CircleDiagnostics::lag_y_ms},
    {"residual", &CircleDiagnostics::residual_rms_um},
};

void expect_same(const CircleDiagnostics& direct, const CircleDiagnostics& designed, const std::string& what) {
  for (const Figure& f : kFigures) {
    const double a = direct.*f.value, b = designed.*f.value;
    if (std::isnan(a) && std::isnan(b)) continue;  // not evaluated by either
    EXPECT_NEAR(a, b, 1e-9 * std::max(1.0, std::abs(a))) << f.name << " (" << what << ")";
  }
  EXPECT_EQ(direct.servo_and_squareness_separated, designed.servo_and_squareness_separated) << what;
  EXPECT_EQ(direct.notes, designed.notes) << what;
}

DiagnosticsOptions options(std::optional<double> pitch_mm) {
  DiagnosticsOptions o;
  o.radius_mm = kR, o.feed_mm_min = kFeed, o.cyclic_pitch_mm = pitch_mm;
  return o;
}

// One design, several paths on its set-point (the draws' use): each as computed directly.
TEST(CircleDesign, EveryPathOnTheSetPointGivesTheDirectDiagnostics) {
  const std::vector<CirclePass> set_point{pass_of(+1, {}, 1000.0, 1), pass_of(-1, {}, 1000.0, 2)};
  for (const std::optional<double> pitch : {std::optional<double>(5.0), std::optional<double>()}) {
    const DiagnosticsOptions o = options(pitch);
    const auto design = circle_design(set_point, o);
    for (std::uint64_t seed = 10; seed < 14; ++seed) {
      Machine m;
      m.backlash_x_mm *= static_cast<double>(seed - 9) / 2.0;  // a play the second round models differently
      const std::vector<CirclePass> passes{pass_of(+1, m, 1000.0, seed), pass_of(-1, m, 1000.0, seed + 100)};
      expect_same(diagnose_circle(passes, o), diagnose_circle(passes, o, *design),
                  "seed " + std::to_string(seed) + (pitch ? ", pitch fixed" : ", pitch searched"));
    }
  }
}

TEST(CircleDesign, OneDirectionAFasterRateAndCreepFeed) {
  {
    const std::vector<CirclePass> one{pass_of(+1, {}, 1000.0, 3)};
    expect_same(diagnose_circle(one, options(5.0)),
                diagnose_circle(one, options(5.0), *circle_design(one, options(5.0))), "one direction");
  }
  {
    // 4 kHz: the fits read every fourth sample, the residuals every one (two walks of records).
    const std::vector<CirclePass> fast{pass_of(+1, {}, 4000.0, 4), pass_of(-1, {}, 4000.0, 5)};
    expect_same(diagnose_circle(fast, options({})),
                diagnose_circle(fast, options({}), *circle_design(fast, options({}))), "4 kHz");
  }
  {
    DiagnosticsOptions creep = options(5.0);
    creep.feed_mm_min = 100.0;
    const std::vector<CirclePass> p{pass_of(+1, {}, 1000.0, 6), pass_of(-1, {}, 1000.0, 7)};
    const CircleDiagnostics direct = diagnose_circle(p, creep);
    EXPECT_GT(direct.stick_slip_um, 0.0);
    expect_same(direct, diagnose_circle(p, creep, *circle_design(p, creep)), "creep feed");
  }
}

TEST(CircleDesign, AnotherSetPointOrANonFinitePathIsRefused) {
  const std::vector<CirclePass> p{pass_of(+1, {}, 1000.0, 8), pass_of(-1, {}, 1000.0, 9)};
  const auto design = circle_design(p, options(5.0));
  const std::vector<CirclePass> shorter{pass_of(+1, {}, 1000.0, 8, 2), pass_of(-1, {}, 1000.0, 9, 2)};
  EXPECT_THROW((void)diagnose_circle(shorter, options(5.0), *design), InputError);
  std::vector<CirclePass> moved = p;
  for (auto& c : moved[0].cmd_mm) c.x() += 0.5;
  EXPECT_THROW((void)diagnose_circle(moved, options(5.0), *design), InputError);
  EXPECT_THROW((void)diagnose_circle(p, options(2.5), *design), InputError);  // another pitch
  std::vector<CirclePass> nan = p;
  nan[1].meas_mm[200].y() = std::nan("");
  try {
    (void)diagnose_circle(nan, options(5.0), *design);
    FAIL() << "a NaN position was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eical::dsp::eval
