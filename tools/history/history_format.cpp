#include "tools/history/history_format.hpp"

#include "dsp/core/key_unit.hpp"
#include "history/record/figure_names.hpp"
#include "history/record/record_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::tools::history_view {
namespace {

using history::FigureChange;
using history::Judgement;

// Decimals that show `u` with one significant digit, two when it begins with 1 or 2.
int decimals_for(double u) {
  if (!(u > 0) || !std::isfinite(u)) return 2;
  const double e = std::floor(std::log10(u));
  const int sig = u / std::pow(10.0, e) < 3.0 ? 2 : 1;
  return std::max(0, sig - 1 - static_cast<int>(e));
}

std::string fixed(double v, int decimals) {
  char b[64];
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;  // no "-0.0"
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

// A value without an uncertainty: three significant digits, never finer than 0.001 (no
// instrument of this kind resolves below a nanometre, whatever the arithmetic printed).
std::string plain(double v) {
  const double a = std::abs(v);
  const int decimals = a > 0 ? std::clamp(2 - static_cast<int>(std::floor(std::log10(a))), 0, 3) : 0;
  return fixed(v, decimals);
}

std::string pad(std::string s, std::size_t n) {
  // Pads by characters as a terminal shows them (µ, ±, ° are two bytes, one column).
  std::size_t cols = 0;
  for (unsigned char c : s) cols += (c & 0xC0) != 0x80;
  if (cols < n) s.append(n - cols, ' ');
  return s;
}

nlohmann::json opt(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }
nlohmann::json opt(const std::optional<std::string>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

std::string verdict_of(const std::optional<std::string>& v, bool degraded) {
  std::string s = v ? *v : "-";
  if (degraded && s != "degraded") s += " (degraded)";
  return s;
}

// Significant changes first (what the user asked), then the rest, each by name.
int rank(Judgement j) {
  switch (j) {
    case Judgement::significant: return 0;
    case Judgement::within_uncertainty: return 1;
    case Judgement::not_judged: return 2;
    case Judgement::missing: return 3;
  }
  return 3;
}

}  // namespace

std::string measure(const std::optional<double>& value, const std::optional<double>& u_k2, const std::string& unit) {
  if (!value) return "n/a";
  const std::string tail = unit.empty() ? "" : " " + unit;
  if (!u_k2) return plain(*value) + tail;
  const int d = decimals_for(*u_k2);
  return fixed(*value, d) + " ± " + fixed(*u_k2, d) + tail;
}

std::string when(const std::string& rfc3339) {
  std::string s = rfc3339;
  if (s.size() == 20 && s[10] == 'T' && s[19] == 'Z') s[10] = ' ', s.pop_back();
  return s;
}

std::string list_text(const std::vector<history::Summary>& rows) {
  if (rows.empty()) return "no results\n";
  std::size_t wm = 7, wr = 3, wp = 7;
  for (const auto& r : rows)
    wm = std::max(wm, r.machine.size()), wr = std::max(wr, r.run_id.size()), wp = std::max(wp, r.program.size());
  std::string out =
      pad("measured (UTC)", 21) + pad("machine", wm + 2) + pad("program", wp + 2) + pad("run", wr + 2) + "verdict\n";
  for (const auto& r : rows)
    out += pad(when(r.measured_at), 21) + pad(r.machine, wm + 2) + pad(r.program, wp + 2) + pad(r.run_id, wr + 2) +
           verdict_of(r.verdict, r.degraded) + "\n";
  out += std::to_string(rows.size()) + " result" + (rows.size() == 1 ? "" : "s") + "\n";
  return out;
}

std::string record_text(const history::Record& r) {
  std::string out = r.machine + " " + r.run_id + " (" + r.program + "), measured " + when(r.measured_at) + " UTC\n";
  out += "  verdict             " + verdict_of(r.verdict, r.degraded) + (r.verdict ? "" : " (the result gives none)") +
         "\n";
  out += "  run directory       " + r.run_path + "\n";
  out += "  software            " + r.software_version.value_or("unknown") + "\n";
  out += "  sensor calibration  " + r.sensor_calibration + "\n";
  std::size_t w = 6;
  for (const auto& f : r.figures) w = std::max(w, f.name.size());
  out += "  " + pad("figure", w + 2) + "value ± U (k = 2)\n";
  for (const auto& f : r.figures)
    out += "  " + pad(f.name, w + 2) + pad(measure(f.value, f.uncertainty_k2, dsp::unit_of_key(f.name)), 24) +
           dsp::label_of_key(f.name) + (f.value ? "" : " (not determined)") + "\n";
  return out;
}

std::string trend_text(const std::string& figure, const std::vector<history::TrendPoint>& points,
                       const std::vector<history::TrendSummary>& summaries) {
  const std::string unit = dsp::unit_of_key(figure);
  std::string out = figure + " (" + dsp::label_of_key(figure) + (unit.empty() ? "" : ", " + unit) +
                    "): " + std::to_string(points.size()) + " result" + (points.size() == 1 ? "" : "s") + "\n";
  if (points.empty()) return out;
  std::size_t wm = 7, wr = 3;
  for (const auto& p : points) wm = std::max(wm, p.machine.size()), wr = std::max(wr, p.run_id.size());
  out += pad("measured (UTC)", 21) + pad("machine", wm + 2) + pad("run", wr + 2) + pad("value ± U (k = 2)", 24) +
         "verdict\n";
  for (const auto& p : points)
    out += pad(when(p.measured_at), 21) + pad(p.machine, wm + 2) + pad(p.run_id, wr + 2) +
           pad(measure(p.value, p.uncertainty_k2, unit), 24) + verdict_of(p.verdict, p.degraded) + "\n";
  for (const auto& s : summaries) {
    out += s.machine + ": ";
    if (!s.first) {
      out += "not determined in any of its " + std::to_string(s.points) + " results\n";
      continue;
    }
    out += measure(s.first->value, s.first->uncertainty_k2, unit) + " (" + when(s.first->measured_at).substr(0, 10) +
           ") → " + measure(s.last->value, s.last->uncertainty_k2, unit) + " (" +
           when(s.last->measured_at).substr(0, 10) + ")";
    if (s.slope_per_30d && s.slope_u_k2)
      out += ", drift " + measure(s.slope_per_30d, s.slope_u_k2, unit) + " per 30 days (" +
             (s.drift_significant ? "significant" : "within its uncertainty") + ")";
    else if (s.span_days < history::kMinDriftSpanDays)
      out += ", drift: the results span less than a day";
    else
      out += ", drift: too few results";
    out += "\n";
  }
  return out;
}

std::string change_sentence(const FigureChange& c) {
  const std::string unit = dsp::unit_of_key(c.name), label = dsp::label_of_key(c.name);
  const std::string tail = unit.empty() ? "" : " " + unit;
  switch (c.judgement) {
    case Judgement::missing:
      if (!c.before && !c.after) return label + ": not determined in either result";
      return label + ": " + (c.before ? measure(c.before, c.u_before, unit) : "not determined") + " → " +
             (c.after ? measure(c.after, c.u_after, unit) : "not determined");
    case Judgement::not_judged: {
      const std::string d = plain(*c.difference);
      return label + " went from " + measure(c.before, c.u_before, unit) + " to " + measure(c.after, c.u_after, unit) +
             ": " + (*c.difference > 0 ? "+" : "") + d + tail + " (no uncertainty on both sides: not judged)";
    }
    default: {
      // Both values at the decimals of the larger uncertainty: "from 6.1 ± 0.4 to 0.8 ± 0.4 µm".
      const int d = decimals_for(std::max(*c.u_before, *c.u_after));
      const int dd = decimals_for(*c.uncertainty_k2);
      return label + " went from " + fixed(*c.before, d) + " ± " + fixed(*c.u_before, d) + " to " + fixed(*c.after, d) +
             " ± " + fixed(*c.u_after, d) + tail + ": " + (*c.difference > 0 ? "+" : "") + fixed(*c.difference, dd) +
             " ± " + fixed(*c.uncertainty_k2, dd) + tail + ", " +
             (c.judgement == Judgement::significant ? "significant" : "within the uncertainty");
    }
  }
}

std::string compare_text(const history::Comparison& c) {
  std::string out = "before: " + c.before.machine + " " + c.before.run_id + " (" + c.before.program + ", " +
                    when(c.before.measured_at) + " UTC, " + verdict_of(c.before.verdict, c.before.degraded) + ")\n";
  out += "after:  " + c.after.machine + " " + c.after.run_id + " (" + c.after.program + ", " +
         when(c.after.measured_at) + " UTC, " + verdict_of(c.after.verdict, c.after.degraded) + ")\n";
  for (const auto& n : c.not_comparable) out += "not the same test: " + n + "\n";
  auto sorted = c.figures;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return rank(a.judgement) < rank(b.judgement); });
  std::size_t significant = 0;
  for (const auto& f : sorted) {
    significant += f.judgement == Judgement::significant;
    out += "  " + change_sentence(f) + "\n";
  }
  out += std::to_string(significant) + " of " + std::to_string(c.figures.size()) +
         " figures changed significantly (|difference| > U, k = 2, U = √(U_before² + U_after²))\n";
  return out;
}

nlohmann::json list_json(const std::string& store, const std::vector<history::Summary>& rows) {
  nlohmann::json r = nlohmann::json::array();
  for (const auto& s : rows) r.push_back(history::summary_json(s));
  return {{"format", "eical-history-list/1"}, {"store", store}, {"results", r}};
}

nlohmann::json trend_json(const std::string& figure, const std::vector<history::TrendPoint>& points,
                          const std::vector<history::TrendSummary>& summaries) {
  nlohmann::json pts = nlohmann::json::array(), sums = nlohmann::json::array();
  for (const auto& p : points)
    pts.push_back({{"machine", p.machine},
                   {"run_id", p.run_id},
                   {"measured_at", p.measured_at},
                   {"value", opt(p.value)},
                   {"uncertainty_k2", opt(p.uncertainty_k2)},
                   {"verdict", opt(p.verdict)},
                   {"degraded", p.degraded}});
  for (const auto& s : summaries)
    sums.push_back({{"machine", s.machine},
                    {"results", s.points},
                    {"determined", s.determined},
                    {"first_run_id", s.first ? nlohmann::json(s.first->run_id) : nlohmann::json(nullptr)},
                    {"last_run_id", s.last ? nlohmann::json(s.last->run_id) : nlohmann::json(nullptr)},
                    {"drift_per_30d", opt(s.slope_per_30d)},
                    {"drift_uncertainty_k2", opt(s.slope_u_k2)},
                    {"drift_significant", s.drift_significant}});
  return {{"format", "eical-history-trend/1"}, {"figure", figure}, {"label", dsp::label_of_key(figure)},
          {"unit", dsp::unit_of_key(figure)},  {"points", pts},    {"machines", sums}};
}

nlohmann::json compare_json(const history::Comparison& c) {
  nlohmann::json figs = nlohmann::json::array();
  for (const auto& f : c.figures)
    figs.push_back({{"name", f.name},
                    {"label", dsp::label_of_key(f.name)},
                    {"unit", dsp::unit_of_key(f.name)},
                    {"before", opt(f.before)},
                    {"before_uncertainty_k2", opt(f.u_before)},
                    {"after", opt(f.after)},
                    {"after_uncertainty_k2", opt(f.u_after)},
                    {"difference", opt(f.difference)},
                    {"difference_uncertainty_k2", opt(f.uncertainty_k2)},
                    {"judgement", history::judgement_name(f.judgement)}});
  return {{"format", "eical-history-compare/1"},
          {"before", history::summary_json(c.before)},
          {"after", history::summary_json(c.after)},
          {"not_comparable", c.not_comparable},
          {"figures", figs}};
}

}  // namespace eical::tools::history_view
