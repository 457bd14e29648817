// A positioning test with the data sheet's sensor model on a machine whose sensor scale lies
// at the far end of its tolerance (drawn machine 7: +486 ppm on x). The strip at mid travel
// once contradicted the standstills (the readings' slope is the scale error, which the
// filter took for velocity), was dropped (psd_disagrees), and the targets were integrated
// apart: 4 to 6 µm of repeatability where the machine has none. Now each crossing gives one
// position: the strip stays, and what is left of R is the noise between the strip and the
// targets, within its U.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"
#include "sim/simulate.hpp"
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/uncertainty/coverage_campaign.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace eical {
namespace {

TEST(PositioningStrip, AScaleAtTheEndOfItsToleranceKeepsTheStripAndInventsNoRepeatability) {
  tools::plan::TestProgram p;
  p.kind = "positioning", p.runs = 3, p.feed_mm_min = 3000.0, p.targets_mm = {0.0, 10.0, 20.0, 30.0};
  p.psd = tools::plan::strips_for(p, 2);
  const sim::Scenario sc = tools::plan::scenario_on_drawn_machine(p, 7);
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = sim::simulate(sc, &truth);
  dsp::AnalysisOptions ao;
  ao.coriolis = sc.coriolis;
  ao.uncertainty.draws = 60;
  const dsp::Analysis a = dsp::analyze_run(run, ao);
  EXPECT_FALSE(a.measurement.supports.psd_disagrees);
  EXPECT_TRUE(a.measurement.supports.psd_crossings_merged);
  const auto measured = dsp::figures_of(a), true_figs = tools::uncertainty::true_figures(run, truth, a);
  for (const char* key : {"positioning.R_um", "positioning.B_um", "positioning.E_um"}) {
    const dsp::FigureValue* m = dsp::find_figure(measured, key);
    const dsp::FigureValue* t = dsp::find_figure(true_figs, key);
    ASSERT_TRUE(m && t) << key;
    const double u = a.uncertainty_k2.at(key).front();
    std::printf("%s: measured %.2f, true %.2f, U %.2f um\n", key, m->values[0], t->values[0], u);
    EXPECT_LE(std::abs(m->values[0] - t->values[0]), u) << key;
  }
  // Repeatability the machine does not have: below 3 µm (it was 7.75 µm without the strip).
  EXPECT_LT(dsp::find_figure(measured, "positioning.R_um")->values[0], 3.0);
}

// 200 mm of travel, the strip at mid travel, drawn machine 3 (x scale about +420 ppm with
// the sensors' temperature). The start is given in the set-point's frame, the strip's
// readings in its own: integrated from one to the other they differ by the scale error
// over 102 mm, 34 µm here. Only the first run sees both; anchored to both, its first
// targets sat 15–20 µm from the other runs', and R was 35.7 µm on a machine without any.
TEST(PositioningStrip, TheFirstRunMeetsTheStripsFrameLikeTheOthers) {
  tools::plan::TestProgram p;
  p.kind = "positioning", p.runs = 5, p.feed_mm_min = 4000.0, p.targets_mm = {0.0, 40.0, 80.0, 120.0, 160.0, 200.0};
  p.psd = tools::plan::strips_for(p, 2);
  const sim::Scenario sc = tools::plan::scenario_on_drawn_machine(p, 3);
  std::vector<Eigen::Vector3d> truth;
  const dsp::Run run = sim::simulate(sc, &truth);
  dsp::AnalysisOptions ao;
  ao.coriolis = sc.coriolis;
  ao.uncertainty.draws = 40;
  const dsp::Analysis a = dsp::analyze_run(run, ao);
  EXPECT_FALSE(a.measurement.supports.psd_disagrees);
  const auto measured = dsp::figures_of(a), true_figs = tools::uncertainty::true_figures(run, truth, a);
  for (const char* key : {"positioning.R_um", "positioning.B_um"}) {
    const dsp::FigureValue* m = dsp::find_figure(measured, key);
    const dsp::FigureValue* t = dsp::find_figure(true_figs, key);
    ASSERT_TRUE(m && t) << key;
    const double u = a.uncertainty_k2.at(key).front();
    std::printf("%s: measured %.2f, true %.2f, U %.2f um\n", key, m->values[0], t->values[0], u);
    EXPECT_LE(std::abs(m->values[0] - t->values[0]), u) << key;
  }
  // What is left of R is the noise between the strip and the far targets (s ≈ 2 µm).
  EXPECT_LT(dsp::find_figure(measured, "positioning.R_um")->values[0], 15.0);
}

}  // namespace
}  // namespace eical
