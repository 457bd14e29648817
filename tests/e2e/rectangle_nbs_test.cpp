// A rectangle's sides under NBS (the other axis held along each side): their straightness,
// direction and corner angles are what the support assumes, so they are not evaluated and
// get no U; without the support they are measured, each with a U the integration noise sets.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"
#include "sim/scenario.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <string>

namespace eical {
namespace {

const char* const kHeld[] = {"rectangle.sides.straightness_um", "rectangle.sides.direction_error_urad",
                             "rectangle.corner_angle_error_urad"};

dsp::Analysis analysed(bool nbs) {
  const dsp::Run run = sim::simulate(sim::rectangle_scenario(40.0, 30.0, 4000.0, "xy", 1, 7));
  dsp::AnalysisOptions o;
  o.nbs = nbs;
  o.uncertainty.draws = 20;
  return dsp::analyze_run(run, o);
}

TEST(RectangleNbs, WhatTheSupportHoldsIsNotEvaluatedAndHasNoU) {
  const dsp::Analysis a = analysed(true);
  ASSERT_TRUE(a.nbs);
  ASSERT_TRUE(a.rectangle);
  for (const char* key : kHeld) {
    EXPECT_EQ(a.not_evaluated.count(key), 1U) << key;
    EXPECT_EQ(a.uncertainty_k2.count(key), 0U) << key;
    EXPECT_NE(a.not_evaluated.at(key).find("NBS"), std::string::npos) << key;
  }
  EXPECT_EQ(a.uncertainty_k2.count("rectangle.corner_error_max_um"), 1U);  // the corners stay measured
}

TEST(RectangleNbs, WithoutTheSupportTheSidesAreMeasuredWithTheirU) {
  const dsp::Analysis a = analysed(false);
  ASSERT_FALSE(a.nbs);
  ASSERT_TRUE(a.rectangle);
  for (const char* key : kHeld) {
    EXPECT_EQ(a.not_evaluated.count(key), 0U) << key;
    ASSERT_EQ(a.uncertainty_k2.count(key), 1U) << key;
    for (double u : a.uncertainty_k2.at(key)) EXPECT_GT(u, 0.0) << key;
  }
  // The integration noise over a 40 mm side at 4 m/min: the direction to tens of µrad at best.
  for (double u : a.uncertainty_k2.at("rectangle.sides.direction_error_urad")) EXPECT_GT(u, 20.0);
}

}  // namespace
}  // namespace eical
