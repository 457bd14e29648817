// The ballbar-size test the issue starts from: R150, F1000, both directions, no supports
// between start and end. On a perfectly accurate simulated machine eical once printed
// G 369 µm "quality: ok"; it must say not measurable, why, and which test would be.
// Also `eical plan` on the command line, and what `eical analyze` exits with.
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "sim/simulate.hpp"
#include "tools/plan/predicted_uncertainty.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <random>

namespace eical {
namespace {

std::string run_cli_status(const std::string& args, int& status) {
  FILE* p = ::popen((std::string(EICAL_CLI) + " " + args + " 2>/dev/null").c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int st = p ? ::pclose(p) : -1;
  status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

TEST(NotMeasurable, BallbarSizeCircleWithoutSupportsSaysSoAndNamesAMeasurableTest) {
  const dsp::Run run = sim::simulate(sim::circle_scenario(150.0, 1000.0, 1, "both"));
  dsp::Analysis a = dsp::analyze_run(run);
  ASSERT_TRUE(a.circle);
  EXPECT_EQ(a.verdict, dsp::Verdict::not_measurable);
  const auto u = a.uncertainty_k2.at("circle.circular_deviation_G_um").at(0);
  std::printf("R150 F1000 both: G = %.1f ± %.1f µm\n", a.circle->circular_deviation_G_um, u);
  EXPECT_GT(u, a.circle->circular_deviation_G_um);  // what it printed as G is within its own noise
  tools::plan::suggest_measurable_test(run, a);
  std::string reasons;
  for (const auto& r : a.verdict_reasons) reasons += r + "\n";
  std::fputs(reasons.c_str(), stdout);
  EXPECT_NE(reasons.find("a circle test is meant to resolve"), std::string::npos);
  EXPECT_NE(reasons.find("a test that would be measurable (eical plan): circle"), std::string::npos);
}

TEST(NotMeasurable, AnalyzeExitsThreeAndPlanPrintsTheNearestMeasurableVariant) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("not-measurable-" + std::to_string(std::random_device{}()));
  // A short circle without strips on data-sheet sensors: U(G) above 10 µm.
  drivers::write_run(sim::simulate(sim::circle_scenario(25.0, 2500.0, 2, "ccw")), dir / "run", {});
  int status = 0;
  const std::string text = run_cli_status("analyze --no-suggest " + (dir / "run").string(), status);
  EXPECT_EQ(status, 3) << text;
  EXPECT_NE(text.find("verdict: NOT MEASURABLE"), std::string::npos) << text;
  EXPECT_NE(text.find(" ± "), std::string::npos) << text;
  const std::string plan = run_cli_status("plan --program circle --radius 25 --repeats 2 --json --draws 40", status);
  EXPECT_EQ(status, 0);
  const auto j = nlohmann::json::parse(plan);
  EXPECT_FALSE(j["prediction"]["measurable"].get<bool>());
  ASSERT_TRUE(j["nearest_measurable"].is_object()) << plan;
  EXPECT_TRUE(j["nearest_measurable"]["measurable"].get<bool>());
  EXPECT_LE(j["nearest_measurable"]["limited_u"].get<double>(), j["nearest_measurable"]["limit"].get<double>());
  std::filesystem::remove_all(dir);
}

// eical plan --resolve: the U the engineer needs replaces what the program must resolve, in
// the verdict of the prediction and in the search for a design that reaches it.
TEST(NotMeasurable, PlanResolveIsTheLimitTheDesignMustReach) {
  tools::plan::TestProgram p;
  p.kind = eical::dsp::ProgramKind::circle, p.radius_mm = 10.0, p.feed_mm_min = 2500.0, p.repeats = 1;
  p.psd = tools::plan::strips_for(p);
  const auto ten = tools::plan::predict(p, 1, 20);
  EXPECT_DOUBLE_EQ(ten.limit, 10.0) << "a circle's G: what it must resolve";
  p.resolve_um = 0.5 * ten.limited_u;
  const auto tight = tools::plan::predict(p, 1, 20);
  EXPECT_DOUBLE_EQ(tight.limit, 0.5 * ten.limited_u);
  EXPECT_FALSE(tight.measurable) << "U " << tight.limited_u << " against " << tight.limit;
  p.resolve_um = 2.0 * ten.limited_u;
  EXPECT_TRUE(tools::plan::predict(p, 1, 20).measurable);
}

}  // namespace
}  // namespace eical
