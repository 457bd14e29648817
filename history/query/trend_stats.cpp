#include "history/query/trend_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>

namespace eical::history {

std::optional<double> epoch_s(const std::string& utc) {
  std::tm tm{};
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  if (std::sscanf(utc.c_str(), "%4d-%2d-%2dT%2d:%2d:%2dZ", &y, &mo, &d, &h, &mi, &s) != 6) return std::nullopt;
  tm.tm_year = y - 1900, tm.tm_mon = mo - 1, tm.tm_mday = d, tm.tm_hour = h, tm.tm_min = mi, tm.tm_sec = s;
  return static_cast<double>(timegm(&tm));
}

namespace {

constexpr double kMonth_s = 30.0 * 86400.0;  // the trend's time unit: 30 days

// Weighted straight line through (t, y) with weights w; slope and its standard deviation
// (scaled by √(χ²/dof) when the scatter exceeds the weights, or from the residuals when
// the weights are not uncertainties). nullopt when the times do not spread.
std::optional<std::pair<double, double>> fit_slope(const std::vector<double>& t, const std::vector<double>& y,
                                                   const std::vector<double>& w, bool weights_are_uncertainties) {
  const std::size_t n = t.size();
  if (n < 2 || (!weights_are_uncertainties && n < 3)) return std::nullopt;
  double sw = 0, st = 0, sy = 0;
  for (std::size_t i = 0; i < n; ++i) sw += w[i], st += w[i] * t[i], sy += w[i] * y[i];
  const double tm = st / sw, ym = sy / sw;
  double stt = 0, sty = 0;
  for (std::size_t i = 0; i < n; ++i) stt += w[i] * (t[i] - tm) * (t[i] - tm), sty += w[i] * (t[i] - tm) * (y[i] - ym);
  if (!(stt > 0)) return std::nullopt;
  const double slope = sty / stt;
  double chi2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - ym - slope * (t[i] - tm);
    chi2 += w[i] * r * r;
  }
  const double dof = static_cast<double>(n) - 2.0;
  double var = 1.0 / stt;  // weights are 1/σ²
  if (!weights_are_uncertainties)
    var = dof > 0 ? chi2 / dof / stt : std::nan("");
  else if (dof > 0 && chi2 / dof > 1.0)
    var *= chi2 / dof;
  if (!std::isfinite(var)) return std::nullopt;
  return std::make_pair(slope, std::sqrt(var));
}

}  // namespace

std::vector<TrendSummary> summarize(const std::vector<TrendPoint>& points) {
  std::map<std::string, std::vector<const TrendPoint*>> by_machine;
  for (const auto& p : points) by_machine[p.machine].push_back(&p);
  std::vector<TrendSummary> out;
  for (const auto& [machine, pts] : by_machine) {
    TrendSummary s;
    s.machine = machine;
    s.points = pts.size();
    std::vector<double> t, y, w;
    bool all_u = true;
    for (const auto* p : pts) {
      if (!p->value) continue;
      const auto ts = epoch_s(p->measured_at);
      if (!ts) continue;
      ++s.determined;
      if (!s.first) s.first = *p;
      s.last = *p;
      t.push_back(*ts / kMonth_s);
      y.push_back(*p->value);
      const bool has_u = p->uncertainty_k2 && *p->uncertainty_k2 > 0;
      all_u &= has_u;
      w.push_back(has_u ? 1.0 / std::pow(*p->uncertainty_k2 / 2.0, 2) : 1.0);
    }
    if (!all_u) std::fill(w.begin(), w.end(), 1.0);
    if (!t.empty())
      s.span_days = (*std::max_element(t.begin(), t.end()) - *std::min_element(t.begin(), t.end())) * 30.0;
    if (s.span_days < kMinDriftSpanDays) {
      out.push_back(std::move(s));
      continue;
    }
    if (const auto f = fit_slope(t, y, w, all_u)) {
      s.slope_per_30d = f->first;
      s.slope_u_k2 = 2.0 * f->second;
      s.drift_significant = std::abs(f->first) > 2.0 * f->second;
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace eical::history
