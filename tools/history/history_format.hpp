#pragma once
// How `eical history` shows results, trends and comparisons: the text a user reads (a
// value with its expanded uncertainty rounded as the GUM suggests: the uncertainty to one
// significant digit, two when it begins with 1 or 2, the value to the same place) and the
// JSON a program reads (eical-history-*/1).
#include "history/query/compare.hpp"
#include "history/query/trend_stats.hpp"
#include "history/record/record.hpp"
#include "history/store/store.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace eical::tools::history_view {

// "6.1 ± 0.4 µm", "3.4 µm" (no uncertainty), "n/a" (not determined).
std::string measure(const std::optional<double>& value, const std::optional<double>& u_k2, const std::string& unit);
// "2026-11-12 09:11:00" (UTC) from the stored RFC 3339 text.
std::string when(const std::string& rfc3339);

std::string list_text(const std::vector<history::Summary>& rows);
std::string record_text(const history::Record& r);
std::string trend_text(const std::string& figure, const std::vector<history::TrendPoint>& points,
                       const std::vector<history::TrendSummary>& summaries);
// "backlash X went from 6.1 ± 0.4 to 0.8 ± 0.4 µm: -5.3 ± 0.6 µm, significant"
std::string change_sentence(const history::FigureChange& c);
std::string compare_text(const history::Comparison& c);

nlohmann::json list_json(const std::string& store, const std::vector<history::Summary>& rows);
nlohmann::json trend_json(const std::string& figure, const std::vector<history::TrendPoint>& points,
                          const std::vector<history::TrendSummary>& summaries);
nlohmann::json compare_json(const history::Comparison& c);

}  // namespace eical::tools::history_view
