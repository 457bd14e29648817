// quality.verdict from the limited figure's uncertainty and the flags; the severity of flags
// (a critical psd_disagrees never looks like the note that H needs both directions); the
// ISO 14253-1 decision against tolerances.
#include "dsp/analysis/verdict.hpp"
#include "dsp/analysis/channel_findings.hpp"
#include "dsp/analysis/conformance.hpp"
#include "dsp/analysis/program_descriptor.hpp"
#include "dsp/core/flag.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

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
  EXPECT_EQ(a.verdict, Verdict::ok);
  EXPECT_TRUE(a.verdict_reasons.empty());
}

TEST(Verdict, NotMeasurableOnlyWhenTheUncertaintyExceedsWhatTheTestResolves) {
  Program p;
  Analysis big = circle(4190.0, 28000.0);  // the ballbar-size circle without supports
  judge(p, big);
  EXPECT_EQ(big.verdict, Verdict::not_measurable);
  ASSERT_EQ(big.verdict_reasons.size(), 1u);
  EXPECT_NE(big.verdict_reasons[0].find("exceeds the 10.0 µm a circle test is meant to resolve"), std::string::npos)
      << big.verdict_reasons[0];
  Analysis at_limit = circle(30.0, 10.0);  // U exactly at the limit still resolves it
  judge(p, at_limit);
  EXPECT_EQ(at_limit.verdict, Verdict::ok);
  Analysis just_over = circle(30.0, 10.01);
  judge(p, just_over);
  EXPECT_EQ(just_over.verdict, Verdict::not_measurable);
}

TEST(Verdict, AFigureBelowItsUncertaintyIsAResultNotAFailure) {
  // A good machine measured well: G = 4.66 ± 5.95 µm says G <= 10.61 µm, which is what the
  // test is for. It once was not_measurable while a worse machine got ok.
  Program p;
  Analysis good = circle(4.66, 5.95);
  judge(p, good);
  EXPECT_EQ(good.verdict, Verdict::ok);
  EXPECT_TRUE(good.verdict_reasons.empty());
  Analysis worse = circle(12.0, 5.95);
  judge(p, worse);
  EXPECT_EQ(worse.verdict, Verdict::ok);
}

TEST(Verdict, WithTolerancesTheDecisionNotTheFixedLimitSaysWhatUMustResolve) {
  // U = 12 µm is above the 10 µm a circle resolves without tolerances, but against a
  // 40 µm tolerance G = 3 ± 12 µm is conformance proven: the banner must not say NOT
  // MEASURABLE over a table that says pass (issue 33).
  Program p;
  const std::vector<FigureTolerance> tol{{"G", {"circle.circular_deviation_G_um"}, 40.0}};
  Analysis wide = circle(3.0, 12.0);
  wide.conformance = decide_conformance(wide, tol);
  judge(p, wide);
  EXPECT_EQ(wide.verdict, Verdict::ok);
  ASSERT_EQ(wide.verdict_reasons.size(), 1u);
  EXPECT_NE(wide.verdict_reasons[0].find("decides its tolerance of 40.0 µm: conformance proven"), std::string::npos)
      << wide.verdict_reasons[0];
  // Straddled (3 + 12 > 10 >= 3 − 12): undecided, and the U is too large for the test.
  Analysis straddled = circle(3.0, 12.0);
  straddled.conformance = decide_conformance(straddled, {{"G", {"circle.circular_deviation_G_um"}, 10.0}});
  judge(p, straddled);
  EXPECT_EQ(straddled.verdict, Verdict::not_measurable);
}

TEST(Verdict, DegradedByACriticalFlagAndNotMeasurableOverridesIt) {
  Program p;
  Analysis a = circle(12.0, 3.0, true);
  a.flags = {{FlagCode::psd_disagrees, {}, {}},
             {FlagCode::figure_null, "circle.circular_hysteresis_H_um", "ISO 230-4 H needs both directions"}};
  judge(p, a);
  EXPECT_EQ(a.verdict, Verdict::degraded);
  ASSERT_EQ(a.verdict_reasons.size(), 1u);
  EXPECT_EQ(a.verdict_reasons[0], flag_text(a.flags[0]));
  Analysis b = circle(1.0, 30.0, true);
  judge(p, b);
  EXPECT_EQ(b.verdict, Verdict::not_measurable);
}

TEST(Verdict, WithoutUncertaintyTheResultIsDegraded) {
  Program p;
  Analysis a = circle(12.0, 3.0);
  a.uncertainty_k2.clear();
  a.uncertainty_note = "no support schedule";
  judge(p, a);
  EXPECT_EQ(a.verdict, Verdict::degraded);
}

TEST(FlagSeverity, CriticalWarningAndNote) {
  EXPECT_EQ(severity(FlagCode::psd_disagrees), FlagSeverity::critical);
  EXPECT_EQ(severity(FlagCode::frames_lost), FlagSeverity::critical);
  EXPECT_EQ(severity(FlagCode::evaluation_failed), FlagSeverity::critical);
  EXPECT_EQ(severity(FlagCode::source_rate), FlagSeverity::critical);
  EXPECT_EQ(severity(FlagCode::no_zupt_window), FlagSeverity::warning);
  EXPECT_EQ(severity(FlagCode::outside_standard), FlagSeverity::warning);
  EXPECT_EQ(severity(FlagCode::one_direction), FlagSeverity::warning);
  EXPECT_EQ(severity(FlagCode::figure_null), FlagSeverity::note);
  EXPECT_STREQ(severity_name(FlagSeverity::critical), "critical");
}

// The verdict reads codes: the same flags with other words decide the same.
TEST(FlagSeverity, TheVerdictDoesNotReadTheText) {
  Program p;
  Analysis a = circle(12.0, 3.0, true);
  a.flags = {{FlagCode::evaluation_failed, "circle", "runs both directions, outside the standard"}};
  judge(p, a);
  EXPECT_EQ(a.verdict, Verdict::degraded);
  ASSERT_EQ(a.verdict_reasons.size(), 1u);  // critical, whatever it says
  Analysis b = circle(12.0, 3.0);
  b.flags = {{FlagCode::one_direction, "circle", "frames_lost: psd_disagrees"}};
  judge(p, b);
  EXPECT_EQ(b.verdict, Verdict::ok);  // a warning, whatever it says
  EXPECT_TRUE(b.verdict_reasons.empty());
}

TEST(FlagSeverity, NothingHoldsThePositionIsNotMeasurable) {
  Program p;
  Analysis a;
  a.degraded = true;
  a.flags = {{FlagCode::position_unsupported, {}, "no standstill and no strip"}};
  judge(p, a);
  EXPECT_EQ(a.verdict, Verdict::not_measurable);
  ASSERT_EQ(a.verdict_reasons.size(), 1u);
  EXPECT_EQ(a.verdict_reasons[0], "circular deviation G is not measurable: no standstill and no strip");
}

// Text is rendered once, from the code, the figure and the detail.
TEST(FlagSeverity, TextIsRenderedFromTheCode) {
  EXPECT_EQ(flag_text({FlagCode::figure_null, "step.scatter_um", "no target was approached twice"}),
            "step.scatter_um: null, no target was approached twice");
  EXPECT_EQ(flag_text({FlagCode::evaluation_failed, "circle", "no stretch sweeps the arc"}),
            "circle: no stretch sweeps the arc");
  EXPECT_EQ(flag_text({FlagCode::position_unsupported, {}, "no standstill"}), "position: null, no standstill");
  EXPECT_EQ(flag_text({FlagCode::unknown_program, "spiral", {}}),
            "program kind 'spiral': no evaluation in this version");
  EXPECT_EQ(flag_text({FlagCode::frames_lost, {}, {}}),
            "frames_lost: the DAQ or driver lost frames (gap integrated with the last value)");
  EXPECT_EQ(flag_text({FlagCode::frames_lost, {}, "12 frames"}), "frames_lost: 12 frames");
  EXPECT_STREQ(code_name(FlagCode::channel_untrusted), "channel");
  EXPECT_STREQ(code_name(FlagCode::unknown_program), "unknown_program");
}

TEST(FlagSeverity, EveryCodeHasItsOwnNameAndAText) {
  std::set<std::string> names;
  for (int c = 0; c <= static_cast<int>(FlagCode::unknown_program); ++c) {
    const auto code = static_cast<FlagCode>(c);
    EXPECT_TRUE(names.insert(code_name(code)).second) << code_name(code) << " twice";
    EXPECT_FALSE(flag_text({code, "circle", {}}).empty()) << code_name(code);
  }
}

TEST(ProgramDescriptor, EveryKindHasItsRowAndEveryEvaluatedProgramALimit) {
  std::set<ProgramKind> kinds;
  for (const ProgramDescriptor& d : program_descriptors()) {
    EXPECT_TRUE(kinds.insert(d.kind).second) << program_kind_name(d.kind) << " twice";
    EXPECT_EQ(&program_descriptor(d.kind), &d) << program_kind_name(d.kind);
    EXPECT_NE(std::string(d.title), "") << program_kind_name(d.kind);
    EXPECT_NE(std::string(d.report_title), "") << program_kind_name(d.kind);
    // A program analyze evaluates has a verdict on its U, and the reverse.
    EXPECT_EQ(d.evaluate != nullptr, d.resolution.has_value()) << program_kind_name(d.kind);
    if (d.resolution) {
      EXPECT_GT(d.resolution->limit, 0.0) << program_kind_name(d.kind);
    }
  }
  EXPECT_EQ(kinds.size(), kProgramKindNames.size());
  EXPECT_EQ(resolution_limit(ProgramKind::identify), nullptr);
  EXPECT_TRUE(program_descriptor(ProgramKind::rectangle).nbs_by_default);
  EXPECT_FALSE(program_descriptor(ProgramKind::circle).nbs_by_default);
}

// The motion's geometry decides which channels a program needs: a positioning test along
// y needs y alone, a circle in zx both z and x.
TEST(ProgramDescriptor, MotionNamesTheAxesAProgramMoves) {
  Program p;
  p.kind = ProgramKind::positioning, p.axis = "y";
  EXPECT_EQ(program_axes(p), 2u);
  p.kind = ProgramKind::circle, p.plane = "zx";
  EXPECT_EQ(program_axes(p), 5u);
  p.kind = ProgramKind::identify;
  EXPECT_EQ(program_axes(p), 7u);
}

TEST(Conformance, Iso14253DecisionRule) {
  EXPECT_EQ(decide(4.0, 5.0, 10.0), Conformance::conforming);       // 9 <= 10
  EXPECT_EQ(decide(5.0, 5.0, 10.0), Conformance::conforming);       // on the limit: proven
  EXPECT_EQ(decide(6.0, 5.0, 10.0), Conformance::undecided);        // 1 .. 11 straddles 10
  EXPECT_EQ(decide(15.0, 5.0, 10.0), Conformance::undecided);       // 10 is not beyond
  EXPECT_EQ(decide(15.01, 5.0, 10.0), Conformance::nonconforming);  // 10.01 > 10
  EXPECT_EQ(decide(1.0, std::nan(""), 10.0), Conformance::undecided);
  EXPECT_STREQ(conformance_words(Conformance::conforming), "conformance proven");
  EXPECT_STREQ(conformance_key(Conformance::nonconforming), "nonconforming");
}

TEST(Conformance, TheRunIsDecidedByItsFigures) {
  Analysis a = circle(4.66, 5.95);
  a.circle->radial_deviation_F_max_um = 3.0;
  a.circle->radial_deviation_F_min_um = -7.0;
  a.uncertainty_k2["circle.radial_deviation_F_max_um"] = {2.0};
  a.uncertainty_k2["circle.radial_deviation_F_min_um"] = {2.5};
  const std::vector<FigureTolerance> t{
      {"G", {"circle.circular_deviation_G_um"}, 15.0},
      {"F", {"circle.radial_deviation_F_max_um", "circle.radial_deviation_F_min_um"}, 10.0},
      {"A", {"positioning.A_um"}, 5.0}};  // not in this run: left out
  ConformanceResult r = decide_conformance(a, t);
  ASSERT_EQ(r.figures.size(), 2u);
  EXPECT_EQ(r.figures[0].decision, Conformance::conforming);        // 4.66 + 5.95 <= 15
  EXPECT_EQ(r.figures[1].key, "circle.radial_deviation_F_min_um");  // the larger magnitude
  EXPECT_DOUBLE_EQ(r.figures[1].magnitude, 7.0);
  EXPECT_EQ(r.figures[1].decision, Conformance::conforming);  // 7 + 2.5 <= 10
  EXPECT_EQ(r.overall, Conformance::conforming);
  r = decide_conformance(a, {{"G", {"circle.circular_deviation_G_um"}, 8.0}});
  EXPECT_EQ(r.overall, Conformance::undecided);
  r = decide_conformance(circle(30.0, 5.0), {{"G", {"circle.circular_deviation_G_um"}, 15.0}, t[1]});
  EXPECT_EQ(r.overall, Conformance::nonconforming);                          // 25 > 15, F absent
  EXPECT_EQ(decide_conformance(a, {t[2]}).overall, Conformance::undecided);  // nothing toleranced
}

TEST(Conformance, AToleranceOverTwoFiguresIsDecidedByTheWorseDecision) {
  // F max 5.0 ± 0.5 conforms to 10; F min -4.9 ± 6 straddles it: F is undecided, and the
  // figure reported is F min although F max is the larger.
  Analysis a = circle(4.0, 1.0);
  a.circle->radial_deviation_F_max_um = 5.0;
  a.circle->radial_deviation_F_min_um = -4.9;
  a.uncertainty_k2["circle.radial_deviation_F_max_um"] = {0.5};
  a.uncertainty_k2["circle.radial_deviation_F_min_um"] = {6.0};
  const ConformanceResult r =
      decide_conformance(a, {{"F", {"circle.radial_deviation_F_max_um", "circle.radial_deviation_F_min_um"}, 10.0}});
  ASSERT_EQ(r.figures.size(), 1u);
  EXPECT_EQ(r.figures[0].key, "circle.radial_deviation_F_min_um");
  EXPECT_EQ(r.figures[0].decision, Conformance::undecided);
  EXPECT_EQ(r.overall, Conformance::undecided);
}

}  // namespace
}  // namespace eical::dsp
