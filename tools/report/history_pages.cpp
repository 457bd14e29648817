#include "tools/report/history_pages.hpp"

#include "dsp/core/float_limits.hpp"
#include "dsp/core/key_unit.hpp"
#include "history/record/figure_names.hpp"
#include "history/record/utc_time.hpp"
#include "tools/history/history_format.hpp"
#include "tools/report/svg.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <map>

namespace eical::tools::report {
namespace {

namespace hv = history_view;

constexpr std::array<const char*, 8> kPalette = {kBlue,     kRed,      kGreen,    "#8e44ad",
                                                 "#d35400", "#16a085", "#2c3e50", kGrey};

// The stored circle trace as polylines: one per stretch of one direction, split where the
// angle wraps (a new revolution), so no line is drawn across the plot.
std::vector<PolarTrace> polar_traces(const history::Record& r, const std::string& label, const char* color) {
  std::vector<PolarTrace> out;
  const auto doc = nlohmann::json::parse(r.document, nullptr, false);
  if (!doc.is_object() || !doc.contains("circle") || !doc["circle"].is_object() || !doc["circle"].contains("trace"))
    return out;
  const auto& t = doc["circle"]["trace"];
  if (!t.contains("angle_deg") || !t.contains("radius_deviation_um")) return out;
  const auto& ang = t["angle_deg"];
  const auto& dev = t["radius_deviation_um"];
  const nlohmann::json dirs = t.value("direction", nlohmann::json::array());
  std::string last_dir;
  for (std::size_t i = 0; i < ang.size() && i < dev.size(); ++i) {
    if (!ang[i].is_number() || !dev[i].is_number()) continue;
    const double a = ang[i].get<double>();
    const std::string dir = i < dirs.size() && dirs[i].is_string() ? dirs[i].get<std::string>() : "";
    if (out.empty() || dir != last_dir || std::abs(a - out.back().angle_deg.back()) > 180.0) {
      out.push_back({out.empty() ? label : "", color, {}, {}});
      last_dir = dir;
    }
    out.back().angle_deg.push_back(a);
    out.back().deviation_um.push_back(dev[i].get<double>());
  }
  return out;
}

std::string short_date(const std::string& t) { return t.substr(0, 10); }
std::string judgement_text(history::Judgement j) {
  switch (j) {
    case history::Judgement::significant: return "significant";
    case history::Judgement::within_uncertainty: return "within the uncertainty";
    case history::Judgement::not_judged: return "not judged (no uncertainty)";
    case history::Judgement::missing: return "not determined";
  }
  return "";
}

// The time axis' unit for the span the results cover: a re-measurement minutes after the
// first reads as minutes, not as 0.00035 days.
struct TimeUnit {
  double seconds;
  const char* name;
};
TimeUnit time_unit_for(double span_s) {
  if (span_s < 2.0 * 3600.0) return {60.0, "minutes"};
  if (span_s < 2.0 * 86400.0) return {3600.0, "hours"};
  return {86400.0, "days"};
}

}  // namespace

std::string trend_plot(const std::string& figure, const std::vector<history::TrendPoint>& points,
                       const std::vector<std::string>& marked) {
  std::optional<double> t0, t1;
  for (const auto& p : points)
    if (const auto s = history::epoch_s(p.measured_at)) {
      if (!t0 || *s < *t0) t0 = *s;
      if (!t1 || *s > *t1) t1 = *s;
    }
  const TimeUnit unit_t = time_unit_for(t0 ? *t1 - *t0 : 0.0);
  // The first result's time below days (minutes from 14:08, not from midnight), else its date.
  const std::string origin = t0 ? history::utc_text(static_cast<std::time_t>(*t0),
                                                    unit_t.seconds < 86400.0 ? "%Y-%m-%d %H:%M UTC" : "%Y-%m-%d")
                                : std::string();
  std::map<std::string, std::size_t> machine_index;
  for (const auto& p : points) machine_index.emplace(p.machine, machine_index.size());
  std::vector<LineSeries> series;
  std::map<std::string, std::size_t> line_of, dots_of;
  for (const auto& [m, k] : machine_index) {
    const char* c = kPalette[k % kPalette.size()];
    line_of[m] = series.size();
    series.push_back({"", c, {}, {}, {}, {}, false, false, 0.8});
    dots_of[m] = series.size();
    series.push_back({m, c, {}, {}, {}, {}, true, false, 1.4, true});
  }
  LineSeries ring{"compared", "#000000", {}, {}, {}, {}, true};
  for (const auto& p : points) {
    const auto s = history::epoch_s(p.measured_at);
    if (!p.value || !s) continue;
    const double x = (*s - *t0) / unit_t.seconds;
    series[line_of[p.machine]].x.push_back(x), series[line_of[p.machine]].y.push_back(*p.value);
    auto& d = series[dots_of[p.machine]];
    d.x.push_back(x), d.y.push_back(*p.value);
    const double u = p.uncertainty_k2.value_or(kNaN);
    d.y_lo.push_back(*p.value - u), d.y_hi.push_back(*p.value + u);
    if (std::find(marked.begin(), marked.end(), p.run_id) != marked.end())
      ring.x.push_back(x), ring.y.push_back(*p.value);
  }
  if (!ring.x.empty()) series.push_back(ring);
  const std::string unit = dsp::unit_of_key(figure);
  return line_plot(series, dsp::label_of_key(figure) + " over time (bars: ± U, k = 2)",
                   std::string(unit_t.name) + " since " + (origin.empty() ? "the first result" : origin),
                   dsp::label_of_key(figure) + (unit.empty() ? "" : " (" + unit + ")"), 760, 320);
}

Page trend_page(const std::string& figure, const std::vector<history::TrendPoint>& points,
                const std::vector<history::TrendSummary>& summaries, const std::string& store) {
  Page page;
  page.title = "Calibration history: trend";
  page.run_id = figure;
  page.subject_label = "Figure";
  page.program = dsp::label_of_key(figure) + ", " + std::to_string(points.size()) + " results";
  page.context = {{"store", store}};
  const std::string unit = dsp::unit_of_key(figure);
  Section s;
  s.heading = dsp::label_of_key(figure) + " over time";
  s.lead = "Each result with its expanded uncertainty (k = 2); one colour per machine.";
  s.svgs.push_back(trend_plot(figure, points));
  Grid drift{"Per machine", {"machine", "first", "last", "drift per 30 days", ""}, {}};
  for (const auto& m : summaries)
    drift.rows.push_back({m.machine, m.first ? hv::measure(m.first->value, m.first->uncertainty_k2, unit) : "n/a",
                          m.last ? hv::measure(m.last->value, m.last->uncertainty_k2, unit) : "n/a",
                          m.slope_per_30d                            ? hv::measure(m.slope_per_30d, m.slope_u_k2, unit)
                          : m.span_days < history::kMinDriftSpanDays ? "results span less than a day"
                                                                     : "too few results",
                          m.slope_per_30d ? (m.drift_significant ? "significant" : "within its uncertainty") : ""});
  s.grids.push_back(drift);
  Grid all{"Results", {"measured (UTC)", "machine", "run", "value ± U (k = 2)", "verdict"}, {}};
  for (const auto& p : points)
    all.rows.push_back({hv::when(p.measured_at), p.machine, p.run_id, hv::measure(p.value, p.uncertainty_k2, unit),
                        p.verdict.value_or("-") + (p.degraded ? " (degraded)" : "")});
  s.grids.push_back(all);
  s.notes.push_back(
      "Drift: a straight line through the results weighted by their uncertainty (σ = U/2), its uncertainty enlarged by "
      "√(χ²/dof) "
      "when they scatter more than their uncertainties allow; significant when the slope exceeds its expanded "
      "uncertainty.");
  page.sections.push_back(std::move(s));
  return page;
}

Page compare_page(const history::Comparison& c, const history::Record& before, const history::Record& after,
                  const std::vector<std::pair<std::string, std::vector<history::TrendPoint>>>& trends,
                  const std::string& store) {
  Page page;
  page.title = "Calibration history: comparison";
  page.run_id = before.run_id + " → " + after.run_id;
  page.subject_label = "Runs";
  page.program =
      before.machine == after.machine ? before.machine + ", " + before.program : before.machine + " → " + after.machine;
  page.context = {{"before", hv::when(before.measured_at) + " UTC, " + before.verdict.value_or("no verdict")},
                  {"after", hv::when(after.measured_at) + " UTC, " + after.verdict.value_or("no verdict")},
                  {"store", store}};
  for (const auto& n : c.not_comparable) page.warnings.push_back("Not the same test: " + n);

  auto polar = polar_traces(before, "before: " + before.run_id + " (" + short_date(before.measured_at) + ")", kGrey);
  auto later = polar_traces(after, "after: " + after.run_id + " (" + short_date(after.measured_at) + ")", kBlue);
  polar.insert(polar.end(), later.begin(), later.end());
  Section p;
  p.heading = "Polar plots overlaid";
  p.lead = "Radius deviation of both results on one ballbar-style plot (both directions of each).";
  const bool both_circles = !later.empty() && later.size() != polar.size();
  if (both_circles) {
    const auto doc = nlohmann::json::parse(after.document, nullptr, false);
    const std::string plane = doc.is_object() && doc.contains("circle") ? doc["circle"].value("plane", "xy") : "xy";
    const std::string a = plane == "zx"   ? "Z"
                          : plane == "yz" ? "Y"
                                          : "X",
                      b = plane == "zx"   ? "X"
                          : plane == "yz" ? "Z"
                                          : "Y";
    p.svgs.push_back(polar_plot(polar, "Radius deviation, " + plane + " plane", "+" + a, "+" + b));
  } else {
    p.notes.push_back("Polar plots need two circular tests with their traces; these results are " + before.program +
                      " and " + after.program + ".");
  }
  Grid sig{"Significant changes", {"figure", "before", "after", "difference"}, {}};
  for (const auto& f : c.figures)
    if (f.judgement == history::Judgement::significant) {
      const std::string unit = dsp::unit_of_key(f.name);
      sig.rows.push_back({dsp::label_of_key(f.name), hv::measure(f.before, f.u_before, unit),
                          hv::measure(f.after, f.u_after, unit), hv::measure(f.difference, f.uncertainty_k2, unit)});
    }
  if (sig.rows.empty())
    p.notes.push_back(
        "No figure changed significantly: every change is within its uncertainty or could not be judged.");
  else
    p.grids.push_back(sig);
  page.sections.push_back(std::move(p));

  Section f;
  f.heading = "Every figure";
  f.lead = "Difference after − before with U = √(U_before² + U_after²) (k = 2); significant when |difference| > U.";
  Grid g{"", {"figure", "before", "after", "difference", "judgement"}, {}};
  for (const auto& fc : c.figures) {
    const std::string unit = dsp::unit_of_key(fc.name);
    g.rows.push_back({dsp::label_of_key(fc.name) + " (" + fc.name + ")", hv::measure(fc.before, fc.u_before, unit),
                      hv::measure(fc.after, fc.u_after, unit),
                      fc.difference ? hv::measure(fc.difference, fc.uncertainty_k2, unit) : "-",
                      judgement_text(fc.judgement)});
  }
  f.grids.push_back(g);
  page.sections.push_back(std::move(f));

  if (!trends.empty()) {
    Section t;
    t.heading = "Trends of the changed figures";
    t.lead = "The machine's history of each significantly changed figure; the two compared results ringed.";
    for (const auto& [name, pts] : trends) t.svgs.push_back(trend_plot(name, pts, {before.run_id, after.run_id}));
    page.sections.push_back(std::move(t));
  }
  return page;
}

}  // namespace eical::tools::report
