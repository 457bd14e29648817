// Two results compared: each figure's difference with the combined expanded uncertainty
// and whether the change is significant; a different test set-up is named. A trend's
// drift: the weighted slope and its uncertainty from points of known drift.
#include "history/query/compare.hpp"
#include "history/query/trend_stats.hpp"
#include "history/record/result_record.hpp"
#include "history_support.hpp"

namespace eical::test {
namespace {

using history::Judgement;

history::Record rec(const std::string& run, const CircleFigures& f, const std::string& machine = "maho-1") {
  return history::record_from_result(circle_result(run, f),
                                     {machine, "2026-11-12T09:11:00Z", "/runs/" + run, std::nullopt, ""});
}

const history::FigureChange& change(const history::Comparison& c, const std::string& name) {
  for (const auto& f : c.figures)
    if (f.name == name) return f;
  throw std::runtime_error("no figure " + name);
}

TEST(HistoryCompare, DifferenceCombinedUncertaintyAndSignificance) {
  CircleFigures before, after;
  before.backlash_x_um = 6.1, before.u_backlash_x_um = 0.4;
  after.backlash_x_um = 0.8, after.u_backlash_x_um = 0.4;
  before.g_um = 6.3, before.u_g_um = 1.1;
  after.g_um = 5.9, after.u_g_um = 1.1;
  const auto c = history::compare(rec("a", before), rec("b", after));
  const auto& b = change(c, "diagnostics.backlash_x_um");
  EXPECT_DOUBLE_EQ(*b.difference, 0.8 - 6.1);
  EXPECT_DOUBLE_EQ(*b.uncertainty_k2, std::sqrt(0.4 * 0.4 + 0.4 * 0.4));
  EXPECT_EQ(b.judgement, Judgement::significant);
  const auto& g = change(c, "circle.circular_deviation_G_um");
  EXPECT_EQ(g.judgement, Judgement::within_uncertainty);  // 0.4 µm against U = 1.56 µm
  EXPECT_EQ(change(c, "circle.radial_deviation_F_max_um").judgement, Judgement::not_judged);  // no U in the result
  EXPECT_EQ(change(c, "circle.circular_hysteresis_H_um").judgement, Judgement::missing);      // null in both
  EXPECT_TRUE(c.not_comparable.empty());
}

TEST(HistoryCompare, ADifferentTestSetUpIsNamed) {
  auto a = rec("a", {}), b = rec("b", {}, "hermle-2");
  auto doc = nlohmann::json::parse(b.document);
  doc["circle"]["feed_mm_min"] = 1000.0;
  b.document = doc.dump();
  const auto c = history::compare(a, b);
  ASSERT_EQ(c.not_comparable.size(), 2u);
  EXPECT_NE(c.not_comparable[0].find("circle.feed_mm_min: 2500"), std::string::npos) << c.not_comparable[0];
  EXPECT_NE(c.not_comparable[1].find("machine: maho-1 → hermle-2"), std::string::npos) << c.not_comparable[1];
}

TEST(HistoryTrend, AKnownDriftIsFoundWithinItsUncertainty) {
  // 0.5 µm per 30 days with U = 0.2 µm noise-free points: the slope exactly, its U from
  // the stated uncertainties (no excess scatter).
  std::vector<history::TrendPoint> pts;
  for (int d = 0; d < 10; ++d) {
    char t[32];
    std::snprintf(t, sizeof t, "2026-01-%02dT00:00:00Z", 1 + 3 * d);
    pts.push_back({"maho-1", "r" + std::to_string(d), t, "ok", false, 2.0 + 0.5 * (3.0 * d) / 30.0, 0.2});
    pts.push_back({"hermle-2", "h" + std::to_string(d), t, "ok", false, 1.0 + (d % 2 ? 0.05 : -0.05), 0.2});
  }
  const auto s = history::summarize(pts);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[1].machine, "maho-1");
  EXPECT_NEAR(*s[1].slope_per_30d, 0.5, 1e-9);
  EXPECT_TRUE(s[1].drift_significant);
  EXPECT_EQ(s[1].first->run_id, "r0");
  EXPECT_EQ(s[1].last->run_id, "r9");
  EXPECT_EQ(s[0].machine, "hermle-2");
  EXPECT_FALSE(s[0].drift_significant) << *s[0].slope_per_30d << " ± " << *s[0].slope_u_k2;
  // U of the slope: 2σ, σ = (U/2)/√Σ(t−t̄)² with t in 30-day units.
  double stt = 0;
  for (int d = 0; d < 10; ++d) stt += std::pow((3.0 * d - 13.5) / 30.0, 2);
  EXPECT_NEAR(*s[1].slope_u_k2, 2.0 * 0.1 / std::sqrt(stt), 1e-9);
}

TEST(HistoryTrend, ResultsOfLessThanADayGiveNoDrift) {
  std::vector<history::TrendPoint> pts;
  for (int s = 0; s < 5; ++s) {
    char t[32];
    std::snprintf(t, sizeof t, "2026-01-01T10:00:%02dZ", 10 * s);
    pts.push_back({"maho-1", "r" + std::to_string(s), t, std::nullopt, false, 15.0 - 0.3 * s, std::nullopt});
  }
  const auto s = history::summarize(pts);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_FALSE(s[0].slope_per_30d);  // not 10^5 µm per 30 days from forty seconds
  EXPECT_LT(s[0].span_days, history::kMinDriftSpanDays);
  EXPECT_EQ(s[0].last->run_id, "r4");
}

}  // namespace
}  // namespace eical::test
