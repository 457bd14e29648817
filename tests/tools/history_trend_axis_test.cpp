// The history trend's time axis follows the span of its results (tools/report/history_pages).
#include "tools/report/history_pages.hpp"

#include <gtest/gtest.h>

namespace eical::tools::report {
namespace {

std::vector<history::TrendPoint> two_results(const std::string& first, const std::string& second) {
  history::TrendPoint a, b;
  a.machine = b.machine = "DMU50-12345";
  a.run_id = "circle-1", b.run_id = "circle-2";
  a.measured_at = first, b.measured_at = second;
  a.value = 8.09, a.uncertainty_k2 = 0.17;
  b.value = 0.03, b.uncertainty_k2 = 0.19;
  return {a, b};
}

TEST(HistoryTrendAxis, AReMeasurementMinutesLaterReadsInMinutesFromTheFirstResult) {
  const std::string svg =
      trend_plot("diagnostics.backlash_x_um", two_results("2026-12-02T14:08:48Z", "2026-12-02T14:09:18Z"), {});
  EXPECT_NE(svg.find("minutes since 2026-12-02 14:08 UTC"), std::string::npos);
}

TEST(HistoryTrendAxis, ResultsMonthsApartReadInDaysFromTheFirstDate) {
  const std::string svg =
      trend_plot("diagnostics.backlash_x_um", two_results("2026-03-02T10:00:00Z", "2026-09-15T10:00:00Z"), {});
  EXPECT_NE(svg.find("days since 2026-03-02<"), std::string::npos);
}

}  // namespace
}  // namespace eical::tools::report
