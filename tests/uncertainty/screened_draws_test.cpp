// A screen on the uncertainty's draws (AnalysisOptions::Uncertainty::stop_above, what eical
// plan's variants use): when U of its figure after the first draws exceeds the bound, the
// draws end there and U is that of those draws; when it does not, every draw runs and U is
// exactly what the unscreened draws give.
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"
#include "tests/support/same_uncertainty.hpp"
#include "tools/plan/predicted_uncertainty.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <string>

namespace eical::tools::plan {
namespace {

constexpr const char* kG = "circle.circular_deviation_G_um";

class ScreenedDraws : public ::testing::Test {
 protected:
  void SetUp() override {
    TestProgram p;  // circle R10 F2500 x2, two PSD strips
    p.repeats = 2;
    p.psd = strips_for(p);
    run_ = sim::simulate(scenario_of(p, 5));
  }
  dsp::Analysis analyse(int draws, const std::optional<dsp::AnalysisOptions::Uncertainty::StopAbove>& stop) const {
    dsp::AnalysisOptions o;
    o.uncertainty.draws = draws;
    o.uncertainty.stop_above = stop;
    return dsp::analyze_run(run_, o);
  }
  dsp::Run run_;
};

TEST_F(ScreenedDraws, AUAboveTheBoundEndsTheDrawsAtTheScreen) {
  const dsp::Analysis eight = analyse(8, std::nullopt);
  ASSERT_TRUE(eight.uncertainty_k2.count(kG)) << eight.uncertainty_note;
  const double u8 = eight.uncertainty_k2.at(kG)[0];
  ASSERT_GT(u8, 0.0);
  const dsp::Analysis screened = analyse(30, dsp::AnalysisOptions::Uncertainty::StopAbove{kG, 0.5 * u8, 8});
  EXPECT_EQ(screened.uncertainty_draws, 8);
  EXPECT_EQ(eight.uncertainty_draws, 8);
  eical::testing::expect_same_uncertainty(eight, screened);
  EXPECT_NE(screened.uncertainty_note.find("8 Monte Carlo draws"), std::string::npos) << screened.uncertainty_note;
}

TEST_F(ScreenedDraws, AUBelowTheBoundRunsEveryDrawAndChangesNothing) {
  const dsp::Analysis all = analyse(30, std::nullopt);
  ASSERT_TRUE(all.uncertainty_k2.count(kG)) << all.uncertainty_note;
  const dsp::Analysis screened =
      analyse(30, dsp::AnalysisOptions::Uncertainty::StopAbove{kG, 100.0 * all.uncertainty_k2.at(kG)[0], 8});
  EXPECT_EQ(screened.uncertainty_draws, 30);
  eical::testing::expect_same_uncertainty(all, screened);
}

TEST_F(ScreenedDraws, AFigureTheRunDoesNotHaveNeverStopsTheDraws) {
  const dsp::Analysis screened = analyse(12, dsp::AnalysisOptions::Uncertainty::StopAbove{"positioning.E_um", 0.0, 4});
  EXPECT_EQ(screened.uncertainty_draws, 12);
}

}  // namespace
}  // namespace eical::tools::plan
