// quality.verdict from the headline figure, its uncertainty and the flags; the severity of
// flags (a critical psd_disagrees never looks like the note that H needs both directions).
#include "dsp/analysis/verdict.hpp"

#include <gtest/gtest.h>

namespace eical::dsp {
namespace {

Analysis circle(double g_um, double u_g_um, bool degraded = false) {
  Analysis a;
  a.circle = eval::CircleResult{};
  a.circle->circular_deviation_G_um = g_um;
  a.circle->direction = "ccw";
  a.uncertainty_k2["circle.circular_deviation_G_um"] = {u_g_um};
  a.degraded = degraded;
  return a;
}

TEST(Verdict, OkWhenTheHeadlineIsResolvedWithinWhatTheTestResolves) {
  Program p;
  Analysis a = circle(12.0, 3.0);
  judge(p, a);
  EXPECT_EQ(a.verdict, "ok");
  EXPECT_TRUE(a.verdict_reasons.empty());
}

TEST(Verdict, NotMeasurableWhenTheUncertaintyExceedsTheLimitOrTheFigure) {
  Program p;
  Analysis big = circle(4190.0, 28000.0);  // the ballbar-size circle without supports
  judge(p, big);
  EXPECT_EQ(big.verdict, "not_measurable");
  ASSERT_EQ(big.verdict_reasons.size(), 2u);
  EXPECT_NE(big.verdict_reasons[0].find("exceeds the 10.0 µm a circle test is meant to resolve"), std::string::npos)
      << big.verdict_reasons[0];
  EXPECT_NE(big.verdict_reasons[1].find("not above its uncertainty"), std::string::npos) << big.verdict_reasons[1];
  Analysis small = circle(1.0, 4.0);  // a machine better than the test can tell
  judge(p, small);
  EXPECT_EQ(small.verdict, "not_measurable");
}

TEST(Verdict, DegradedByACriticalFlagAndNotMeasurableOverridesIt) {
  Program p;
  Analysis a = circle(12.0, 3.0, true);
  a.flags = {"psd_disagrees: the PSD readings contradict the integrated motion",
             "circle.circular_hysteresis_H_um: null, ISO 230-4 H needs both directions"};
  judge(p, a);
  EXPECT_EQ(a.verdict, "degraded");
  ASSERT_EQ(a.verdict_reasons.size(), 1u);
  EXPECT_EQ(a.verdict_reasons[0].rfind("psd_disagrees", 0), 0u);
  Analysis b = circle(1.0, 30.0, true);
  judge(p, b);
  EXPECT_EQ(b.verdict, "not_measurable");
}

TEST(Verdict, WithoutUncertaintyTheResultIsDegraded) {
  Program p;
  Analysis a = circle(12.0, 3.0);
  a.uncertainty_k2.clear();
  a.uncertainty_note = "no support schedule";
  judge(p, a);
  EXPECT_EQ(a.verdict, "degraded");
}

TEST(FlagSeverity, CriticalWarningAndNote) {
  EXPECT_EQ(flag_severity("psd_disagrees: the PSD readings contradict"), FlagSeverity::critical);
  EXPECT_EQ(flag_severity("frames_lost: the DAQ lost frames"), FlagSeverity::critical);
  EXPECT_EQ(flag_severity("circle: no stretch between two M102 marks sweeps the programmed arc"),
            FlagSeverity::critical);
  EXPECT_EQ(flag_severity("no_zupt_window: no rest after the motion"), FlagSeverity::warning);
  EXPECT_EQ(flag_severity("positioning: 3 runs per target and direction, ISO 230-2 asks for 5: evaluated by its "
                          "formulas, outside the standard"),
            FlagSeverity::warning);
  EXPECT_EQ(flag_severity("circle.circular_hysteresis_H_um: null, ISO 230-4 H needs both directions"),
            FlagSeverity::note);
  EXPECT_STREQ(severity_name(FlagSeverity::critical), "critical");
}

TEST(Verdict, EveryProgramHasALimit) {
  for (const char* kind : {"circle", "positioning", "step", "rectangle", "freeform"}) {
    const ResolutionLimit* l = resolution_limit(kind);
    ASSERT_NE(l, nullptr) << kind;
    EXPECT_GT(l->limit, 0.0);
  }
  EXPECT_EQ(resolution_limit("identify"), nullptr);
}

}  // namespace
}  // namespace eical::dsp
