// The Q-format integer path (static compensation, bias, integrators, two-stage read-out)
// against the double path: bit-exact, deterministic, ≤ 1 nm over a 10 s run; saturation
// flagged, never wrapped.
#include "pipeline_test_util.hpp"

#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

namespace eical {
namespace {

using testutil::config_for;
using testutil::max_difference_um;
using testutil::run_pipeline;

TEST(FixedPointPipeline, TenSecondsWithinOneNanometreOfTheDoublePath) {
  // R10 circle at 2.5 m/min, 7 revolutions (> 10 s of integration), with sensor noise and
  // the 24-bit ADC, both sensors warming (the temperature terms recomputed every sample)
  // and cross terms to invert.
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 7);
  for (auto& t : sc.truth) t.temperature = {22.0, 3.0, 60.0};
  const dsp::Run run = sim::simulate(sc);
  auto cfg = config_for(run);
  cfg.zupt = false;  // ZUPT is offline and in double in both; compare the streaming paths
  cfg.calibration[1].cross_g_per_g(0, 1) = 1e-3;
  cfg.calibration[1].cross_g_per_g(1, 0) = -2e-3;
  const auto d = run_pipeline(run, cfg);
  cfg.arithmetic = dsp::Arithmetic::fixed_q;
  const auto q = run_pipeline(run, cfg);
  const auto q2 = run_pipeline(run, cfg);
  ASSERT_EQ(d.pos_mm.size(), q.pos_mm.size());
  const double seconds = static_cast<double>(q.pos_mm.size()) / run.fs_hz();
  const double dev_nm = max_difference_um(d, q) * 1000.0;
  std::printf("fixed point vs double over %.1f s of integration: max |dx| = %.4f nm\n", seconds, dev_nm);
  EXPECT_GE(seconds, 10.0);
  EXPECT_LE(dev_nm, 1.0);
  EXPECT_FALSE(q.degraded) << (q.flags.empty() ? "" : flag_text(q.flags.front()));
  // Deterministic: a second run gives the same bits.
  ASSERT_EQ(q2.pos_mm.size(), q.pos_mm.size());
  EXPECT_EQ(std::memcmp(q.pos_mm.data(), q2.pos_mm.data(), q.pos_mm.size() * sizeof(Eigen::Vector3d)), 0);
}

TEST(FixedPointPipeline, WithZuptAndNoDynamicsTooAndUnsupportedModesAreRefused) {
  const dsp::Run run = sim::simulate(sim::step_scenario(0.0, 50.0, 3250.0, 1));
  auto cfg = config_for(run);
  cfg.dynamic = dsp::DynamicComp::none;
  const auto d = run_pipeline(run, cfg);
  cfg.arithmetic = dsp::Arithmetic::fixed_q;
  const auto q = run_pipeline(run, cfg);
  EXPECT_LE(max_difference_um(d, q), 0.001);
  cfg.dynamic = dsp::DynamicComp::velocity_level;
  EXPECT_THROW(dsp::Pipeline{cfg}, dsp::InputError);
  cfg.dynamic = dsp::DynamicComp::two_stage;
  cfg.coriolis = true;
  EXPECT_THROW(dsp::Pipeline{cfg}, dsp::InputError);
}

TEST(FixedPointPipeline, OverflowSaturatesAndFlagsTheResult) {
  // Deliberate overflow: the head's x channel at the int32 limit for the whole motion
  // (2072 g with a 24-bit-lsb scale: v² and v³ leave Q44, then the velocity leaves Q40).
  dsp::Run run = sim::simulate(sim::step_scenario(0.0, 50.0, 3250.0, 1));
  for (auto& f : run.frames)
    if (f.sample_index > 6000) f.accel_counts[3] = std::numeric_limits<std::int32_t>::max();
  auto cfg = config_for(run);
  cfg.arithmetic = dsp::Arithmetic::fixed_q;
  dsp::Pipeline p(cfg);
  for (const auto& f : run.frames) p.step(f);
  EXPECT_TRUE(p.quality_bits() & dsp::quality_flag::fixed_saturated);
  const auto m = p.finish();
  EXPECT_TRUE(m.degraded);
  bool named = false;
  for (const auto& f : m.flags) named |= f.code == dsp::FlagCode::fixed_saturated;
  EXPECT_TRUE(named);
  // Saturated, not wrapped: the position runs one way and stays finite.
  for (const auto& x : m.pos_mm) EXPECT_TRUE(x.allFinite());
  EXPECT_GT(std::abs(m.pos_mm.back()[0] - m.pos_mm.front()[0]),
            1000.0);  // clamped far away (mm), not wrapped to small values
}

}  // namespace
}  // namespace eical
