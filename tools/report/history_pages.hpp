#pragma once
// The calibration history as HTML pages (eical history trend --html, compare --html), built
// from the same helpers as the run reports: a figure's trend over time with its uncertainty
// as error bars, one series per machine; and two results compared: their polar plots
// overlaid, every figure's change with its combined uncertainty, and the trend of each
// significantly changed figure with the two results marked.
#include "history/query/compare.hpp"
#include "history/query/trend_stats.hpp"
#include "history/record/record.hpp"
#include "tools/report/html.hpp"

#include <string>
#include <utility>
#include <vector>

namespace eical::tools::report {

// The trend plot of one figure (an SVG element); `marked` run ids are ringed.
std::string trend_plot(const std::string& figure, const std::vector<history::TrendPoint>& points,
                       const std::vector<std::string>& marked = {});

Page trend_page(const std::string& figure, const std::vector<history::TrendPoint>& points,
                const std::vector<history::TrendSummary>& summaries, const std::string& store);

// `trends`: figure name → its points on the machine (for the significantly changed figures).
Page compare_page(const history::Comparison& c, const history::Record& before, const history::Record& after,
                  const std::vector<std::pair<std::string, std::vector<history::TrendPoint>>>& trends,
                  const std::string& store);

}  // namespace eical::tools::report
