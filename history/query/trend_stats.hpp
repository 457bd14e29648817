#pragma once
// What a trend says: per machine, the first and the last value and the drift, a straight
// line fitted over time weighted by each point's uncertainty (σ = U/2). When the points
// scatter more than their uncertainties allow (χ²/dof > 1) the slope's uncertainty grows
// by √(χ²/dof); points without an uncertainty are fitted unweighted, the slope's
// uncertainty then from the residuals alone (needs three points). A drift is significant
// when |slope| exceeds its expanded uncertainty (k = 2). Results that span less than a day
// give no drift: a rate per 30 days from minutes of data would be an extrapolation, not a
// measurement.
#include "history/store/store.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::history {

struct TrendSummary {
  std::string machine;
  std::size_t points = 0, determined = 0;           // results, of which with a value
  std::optional<TrendPoint> first, last;            // the first and last with a value
  std::optional<double> slope_per_30d, slope_u_k2;  // figure unit per 30 days
  bool drift_significant = false;
  double span_days = 0.0;  // first to last result with a value
};

inline constexpr double kMinDriftSpanDays = 1.0;

// One summary per machine of the points, machines in order of name.
std::vector<TrendSummary> summarize(const std::vector<TrendPoint>& points);

// Seconds since 1970 of an RFC 3339 UTC text ("YYYY-MM-DDTHH:MM:SSZ"); nullopt otherwise.
std::optional<double> epoch_s(const std::string& utc);

}  // namespace eical::history
