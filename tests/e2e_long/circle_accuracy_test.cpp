// Simulator → pipeline → circle evaluation, against the simulator's truth (the reference
// channel holds the true relative position). The accuracy figures are the issue's
// acceptance numbers; the main job prints the same figure for its run.
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdio>

namespace eical {
namespace {

sim::Scenario ideal_adc(sim::Scenario sc) {
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;  // quantisation far below the figures checked
  return sc;
}

// RMS of measured − true position over the trace (µm), optionally only between the first
// and the last M102 (the revolutions at constant feed).
double position_rms_um(const dsp::Measurement& m, bool steady_only = false) {
  std::int64_t from = INT64_MIN, to = INT64_MAX;
  if (steady_only) {
    for (const auto& t : m.triggers)
      if (t.code == 102) from = from == INT64_MIN ? t.sample_index : from, to = t.sample_index;
  }
  double ss = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < m.pos_mm.size(); ++i)
    if (m.sample_index[i] >= from && m.sample_index[i] <= to) ss += (m.pos_mm[i] - m.ref_mm[i]).squaredNorm(), ++n;
  return std::sqrt(ss / static_cast<double>(n)) * 1000.0;
}

TEST(CircleAccuracy, NoiseFreeTwoStageCompensationIsExact) {
  const dsp::Run run = sim::simulate(ideal_adc(sim::circle_scenario()));
  // The compensation alone: ZUPT reads the last 0.1 µm/s of the stop's ringing at the
  // onset of the standstill as a velocity error (within its σ at any real noise).
  dsp::AnalysisOptions compensation_only;
  compensation_only.zupt = false;
  const auto a = dsp::analyze_run(run, compensation_only);
  ASSERT_TRUE(a.circle && a.circle_accuracy_rms_um) << (a.flags.empty() ? "" : flag_text(a.flags.front()));
  EXPECT_LT(*a.circle_accuracy_rms_um, 0.01);
  EXPECT_LT(position_rms_um(a.measurement, true), 0.01);
  // Over the whole move the (6-38) expansion's neglected third-order term shows at the
  // jerk steps of the feed ramps: d³/6 · Δjerk ≈ 0.5 µm for a few milliseconds.
  EXPECT_LT(position_rms_um(a.measurement), 0.1);
  EXPECT_LT(a.circle->circular_deviation_G_um, 0.01);
  EXPECT_EQ(a.circle->revolutions, 5);
  EXPECT_FALSE(a.degraded) << (a.flags.empty() ? "" : flag_text(a.flags.front()));

  dsp::AnalysisOptions none = compensation_only;
  none.dynamic = dsp::DynamicComp::none;
  const auto b = dsp::analyze_run(run, none);
  const double uncompensated = position_rms_um(b.measurement);
  std::printf(
      "position error RMS on the R10 circle: two-stage %.4f um (steady revolutions %.4f um), uncompensated %.1f um\n",
      position_rms_um(a.measurement), position_rms_um(a.measurement, true), uncompensated);
  // The thesis reports about 150 µm uncompensated on this circle (Bild 7-14): the delay
  // of 3.9 ms alone is 160 µm at 41.7 mm/s.
  EXPECT_GT(uncompensated, 50.0);
}

TEST(CircleAccuracy, ZuptRemovesAConstantBiasErrorAfterTheRestWindow) {
  sim::Scenario sc = ideal_adc(sim::circle_scenario());
  dsp::Run run = sim::simulate(sc);
  // +1 µg on the head's x channel from the first motion on (a bias step the rest window
  // cannot see): counts per g = k1 / lsb.
  const double counts_per_ug = sc.truth[1].spec.k1_v_per_g[0] / sc.meta.acquisition.adc_lsb_volt * 1e-6;
  for (auto& f : run.frames)
    if (f.sample_index >= 5000) f.accel_counts[3] += static_cast<std::int32_t>(std::lround(counts_per_ug));
  // The filter is told what was injected: a step, no random walk on top.
  dsp::PipelineConfig cfg = dsp::pipeline_config(run.meta, run.frames.size());
  cfg.fusion.bias_walk_um_s2_rts = 0.0;
  auto run_with = [&](bool zupt) {
    cfg.zupt = zupt;
    dsp::Pipeline p(cfg);
    for (const auto& f : run.frames) p.step(f);
    return position_rms_um(p.finish());
  };
  const double without = run_with(false);
  const double with = run_with(true);
  std::printf("1 ug bias step: position error RMS without ZUPT %.1f um, with ZUPT %.3f um\n", without, with);
  EXPECT_GT(without, 50.0);
  EXPECT_LT(with, 0.5);
}

TEST(CircleAccuracy, RadiusDeviationWithinFiveMicrometresAtTheDataSheetNoise) {
  // The acceptance figure: RMS of (measured − true) radius deviation ≤ 5 µm with
  // 0.4 µg/√Hz per sensor, 10 kHz, 24-bit ADC. Three fixed seeds (deterministic).
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto a = dsp::analyze_run(sim::simulate(sim::circle_scenario(10.0, 2500.0, 5, "ccw", seed)));
    ASSERT_TRUE(a.circle_accuracy_rms_um);
    std::printf("seed %llu: radius deviation error RMS %.2f um, G %.2f um, mean radius deviation %.2f um\n",
                static_cast<unsigned long long>(seed), *a.circle_accuracy_rms_um, a.circle->circular_deviation_G_um,
                a.circle->radius_mean_deviation_um);
    EXPECT_LE(*a.circle_accuracy_rms_um, 5.0) << "seed " << seed;
  }
}

TEST(CircleAccuracy, BadFramesDegradeTheResultWithNamedReasons) {
  dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 2));
  run.frames[20000].flags |= dsp::frame_flag::accel_saturated;
  run.frames[20001].flags |= dsp::frame_flag::accel_missing;
  run.frames.erase(run.frames.begin() + 25000, run.frames.begin() + 25010);
  run.frames[25000].flags |= dsp::frame_flag::gap_before;
  const auto a = dsp::analyze_run(run);
  EXPECT_TRUE(a.degraded);
  std::string all;
  for (const auto& f : a.flags) all += flag_text(f) + "\n";
  EXPECT_NE(all.find("accel_saturated"), std::string::npos) << all;
  EXPECT_NE(all.find("accel_missing"), std::string::npos) << all;
  EXPECT_NE(all.find("frames_lost"), std::string::npos) << all;
  ASSERT_TRUE(a.circle_accuracy_rms_um);  // still evaluated: one held sample and 1 ms of gap
  EXPECT_LT(*a.circle_accuracy_rms_um, 10.0);
}

TEST(CircleAccuracy, RunWithoutTriggersIsFlaggedNotCrashed) {
  dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 1));
  for (auto& f : run.frames) f.trigger = 0;
  const auto a = dsp::analyze_run(run);
  EXPECT_TRUE(a.degraded);
  EXPECT_FALSE(a.circle.has_value());
  ASSERT_FALSE(a.flags.empty());
  EXPECT_TRUE(dsp::any_critical(a.flags)) << flag_text(a.flags.front());
}

}  // namespace
}  // namespace eical
