// The uncertainty's building blocks: the sensor model's covariance, the coarse schedule,
// the error field's draws against the smoother's own posterior covariance (when the truth
// is the fusion's model, the simulation smoother's spread is that covariance), the model
// responses, the expanded uncertainty of linear and range-like figures, and the one rule
// of when a figure is resolved.
#include "dsp/analysis/figure_uncertainty.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/sensor_model_covariance.hpp"
#include "dsp/fusion/error_covariance.hpp"
#include "dsp/uncertainty/coarse_schedule.hpp"
#include "dsp/uncertainty/error_field.hpp"
#include "dsp/uncertainty/resolved.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace eical::dsp::uncertainty {
namespace {

namespace sf = fusion::schedule_flag;

TEST(SensorModelCovariance, NamesRoundTripAndTheDataSheetIsUniformWithinItsTolerance) {
  for (int p = 0; p < kModelParameters; ++p) EXPECT_EQ(parameter_index(parameter_name(p)), p) << parameter_name(p);
  EXPECT_EQ(parameter_name(error_index(1, 0, 2)), "head.E_xz");
  EXPECT_EQ(parameter_name(damping_index(0)), "table.c1_s");
  EXPECT_EQ(parameter_name(tc_bias_index(1, 2)), "head.tc_bias_z_ug_per_c");
  EXPECT_EQ(parameter_index("table.E_xq"), -1);
  const SensorSpec sheet[2];
  const DatasheetTolerance t;
  const SensorModelCovariance c = datasheet_covariance(sheet, 10000.0, t);
  // x, y scale: k1 and the gravity cross term k_zx·g, each uniform: u² = (a² + b²)/3.
  EXPECT_NEAR(c.sigma(error_index(0, 0, 0)),
              std::sqrt((t.scale * t.scale + t.cross2_g_per_g2 * t.cross2_g_per_g2) / 3.0), 1e-12);
  EXPECT_NEAR(c.sigma(error_index(1, 0, 1)),
              std::sqrt((t.cross_g_per_g * t.cross_g_per_g + t.mounting_rad * t.mounting_rad) / 3.0), 1e-12);
  // 2ζ/ω0 = 225 µs; ±0.01 of ζ and ±1 % of f0 make about 2 µs.
  EXPECT_GT(c.sigma(damping_index(0)), 1e-6);
  EXPECT_LT(c.sigma(damping_index(0)), 3e-6);
  EXPECT_EQ(c.sigma(kDelayIndex), 0.0);  // a linear-phase FIR's delay is exact
  EXPECT_NEAR(c.sigma(tc_bias_index(0, 1)), t.tc_bias_ug_per_c / std::sqrt(3.0), 1e-9);
  EXPECT_EQ((c.covariance - c.covariance.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(ResolvedRule, MagnitudeAboveTheExpandedUncertainty) {
  EXPECT_TRUE(resolved(2.0, 1.0));
  EXPECT_TRUE(resolved(-2.0, 1.0));
  EXPECT_FALSE(resolved(1.0, 1.0));
  EXPECT_FALSE(resolved(0.5, 1.0));
  EXPECT_FALSE(resolved(kNaN, 1.0));
  EXPECT_FALSE(resolved(5.0, kNaN));
}

// A 2 s trace at 1 kHz: standstills in the first and last 0.2 s, a PSD strip fix along x
// in the middle (10 samples), moving elsewhere.
struct Trace {
  std::vector<std::int64_t> idx;
  fusion::SupportSchedule schedule;
  std::vector<Eigen::Vector3d> pos, vel;
};

Trace synthetic(bool with_fix) {
  Trace t;
  const std::size_t n = 2000;
  for (std::size_t k = 0; k < n; ++k) {
    t.idx.push_back(static_cast<std::int64_t>(k));
    const bool rest = k < 200 || k >= 1800;
    t.schedule.flags.push_back(rest ? sf::rest : 0);
    t.schedule.zupt_sigma_um_s.push_back(0.0F);
    const double s = static_cast<double>(k) / 1000.0;
    t.pos.emplace_back(rest ? (k < 200 ? 0.0 : 40.0) : 40.0 * (s - 0.2) / 1.6, 0.0, 0.0);
    t.vel.emplace_back(rest ? 0.0 : 25.0, 0.0, 0.0);
  }
  t.schedule.flags[200] |= sf::move_start;
  if (with_fix)
    for (std::size_t k = 995; k < 1005; ++k) t.schedule.fixes.push_back({k, 0, 0.0, 0.2, 0, 0.0});
  return t;
}

ErrorFieldInput input_for(const Trace& t, const fusion::ErrorModel& m) {
  ErrorFieldInput in;
  in.schedule = &t.schedule;
  in.sample_index = &t.idx;
  in.pos_mm = &t.pos;
  in.vel_mm_s = &t.vel;
  in.fs_hz = 1000.0;
  in.model = m;
  in.start_bias_sigma_um_s2 = Eigen::Vector3d::Constant(5.0);
  in.g_mps2 = 9.81;
  // The truth the draws simulate is the fusion's own model.
  in.sensor_noise_ug_per_rthz[0] = in.sensor_noise_ug_per_rthz[1] = m.accel_noise_um_s2_rthz / std::sqrt(2.0) / 9.81;
  in.rel_noise_ug_per_rthz = m.accel_noise_um_s2_rthz / 9.81;  // as if measured at rest
  in.bias_walk_ug_per_rts[0] = in.bias_walk_ug_per_rts[1] = m.bias_walk_um_s2_rts / std::sqrt(2.0) / 9.81;
  in.max_coarse = 2000;  // no coarsening: compare with the fine posterior
  return in;
}

TEST(ErrorField, NoiseDrawsSpreadAsTheSmoothersPosteriorWhenTheTruthIsItsModel) {
  const Trace t = synthetic(true);
  fusion::ErrorModel m;
  // The truth starts at the set-point (ErrorCovariance's convention); a filter that assumes
  // it may be 2 µm off spreads the strip's correction differently: it is not the optimum.
  m.start_position_um = 0.0;
  const ErrorFieldInput in = input_for(t, m);
  // The model's part off: only the noise.
  ErrorFieldInput noise_only = in;
  noise_only.model_covariance.covariance.setZero();
  noise_only.model_covariance.psd_offset_sigma_um = 0.0;
  const ErrorField f(noise_only);
  const std::vector<double> at{600.0, 1000.0, 1500.0};
  std::mt19937_64 rng(7);
  std::vector<Eigen::Vector3d> e;
  Eigen::Vector3d ss = Eigen::Vector3d::Zero();
  const int draws = 600;
  for (int d = 0; d < draws; ++d) {
    f.draw(rng, at, e);
    for (int i = 0; i < 3; ++i) ss[i] += e[static_cast<std::size_t>(i)].x() * e[static_cast<std::size_t>(i)].x();
  }
  fusion::ErrorModel mc = m;
  const fusion::ErrorCovariance cov(t.schedule, t.idx, 1000.0, mc, in.start_bias_sigma_um_s2);
  for (int i = 0; i < 3; ++i) {
    const double sigma = std::sqrt(ss[i] / draws),
                 expected = cov.sigma_um(static_cast<std::size_t>(at[static_cast<std::size_t>(i)]), 0);
    std::printf("trace sample %.0f: draws σ %.3f µm, posterior σ %.3f µm\n", at[static_cast<std::size_t>(i)], sigma,
                expected);
    EXPECT_NEAR(sigma / expected, 1.0, 0.15) << "at " << at[static_cast<std::size_t>(i)];
  }
}

TEST(ErrorField, DrawsAreSeededAndDeterministic) {
  const Trace t = synthetic(false);
  const ErrorField f(input_for(t, fusion::ErrorModel{}));
  std::mt19937_64 a(3), b(3);
  std::vector<Eigen::Vector3d> ea, eb;
  f.draw(a, {500.0, 1200.0}, ea);
  f.draw(b, {500.0, 1200.0}, eb);
  EXPECT_EQ(ea, eb);
}

TEST(ErrorField, AScaleErrorWithoutPositionSupportsStaysAsItIs) {
  // No strip: standstills only fix the velocity, so E·Δx is left whole.
  const Trace t = synthetic(false);
  ErrorFieldInput in = input_for(t, fusion::ErrorModel{});
  in.rel_noise_ug_per_rthz = 1e-12, in.bias_walk_ug_per_rts[0] = in.bias_walk_ug_per_rts[1] = 1e-12;
  in.model.accel_noise_um_s2_rthz = 1e-9, in.model.bias_walk_um_s2_rts = 1e-9;
  in.sensor_noise_ug_per_rthz[0] = in.sensor_noise_ug_per_rthz[1] = 1e-12;
  in.model_covariance.covariance.setZero();
  in.model_covariance.covariance(error_index(0, 0, 0), error_index(0, 0, 0)) = 1e-8;  // σ 100 ppm
  in.model_covariance.psd_offset_sigma_um = 0.0;
  const ErrorField f(in);
  std::mt19937_64 rng(1);
  double ss_end = 0.0;
  const int draws = 400;
  std::vector<Eigen::Vector3d> e;
  for (int d = 0; d < draws; ++d) {
    f.draw(rng, {1900.0}, e);
    ss_end += e[0].x() * e[0].x();
  }
  // 100 ppm of 40 mm = 4 µm.
  EXPECT_NEAR(std::sqrt(ss_end / draws), 4.0, 0.4);
}

TEST(CoarseSchedule, BlocksCombineStandstillsAndFixesByTheirInformation) {
  Trace t = synthetic(true);
  fusion::ErrorModel m;
  const CoarseSchedule c = coarsen(t.schedule, t.idx, m, 10, kDefaultFs_hz);
  ASSERT_EQ(c.sample_index.size(), 200u);
  EXPECT_EQ(c.sample_index[0], 9);
  EXPECT_TRUE(c.schedule.flags[0] & sf::rest);
  // Ten standstill samples of σ 2 µm/s: one of 2/√10.
  EXPECT_NEAR(c.schedule.zupt_sigma_um_s[0], m.zupt_sigma_um_s / std::sqrt(10.0), 1e-6);
  // The fix samples 995..1004 fall into two blocks.
  ASSERT_EQ(c.schedule.fixes.size(), 2u);
  const double each = std::hypot(0.2, m.psd_floor_um);
  EXPECT_NEAR(c.schedule.fixes[0].sigma_um, each / std::sqrt(5.0), 1e-9);
  EXPECT_NEAR(c.fix_noise_um[0], each / std::sqrt(5.0), 1e-9);
}

}  // namespace
}  // namespace eical::dsp::uncertainty
