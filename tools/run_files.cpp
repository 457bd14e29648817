#include "tools/run_files.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/program_descriptor.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/key_unit.hpp"
#include "dsp/uncertainty/resolved.hpp"
#include "tools/exit_codes.hpp"
#include "tools/figure_text.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace eical::tools {

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp.string() + ": cannot create: " + std::strerror(errno));
    os << text;
    if (!os.flush()) throw std::runtime_error(tmp.string() + ": write failed: " + std::strerror(errno));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
}

int verdict_exit_code(dsp::Verdict verdict) {
  switch (verdict) {
    case dsp::Verdict::not_measurable: return kExitNotMeasurable;
    case dsp::Verdict::degraded: return kExitDegraded;
    case dsp::Verdict::ok: return kExitOk;
  }
  return kExitOk;
}

int result_exit_code(dsp::Verdict verdict, const std::optional<dsp::Conformance>& conformance) {
  if (verdict != dsp::Verdict::ok || !conformance) return verdict_exit_code(verdict);
  switch (*conformance) {
    case dsp::Conformance::conforming: return kExitOk;
    case dsp::Conformance::nonconforming: return kExitNonConforming;
    case dsp::Conformance::undecided: return kExitUndecided;
  }
  return kExitOk;
}

namespace {

// A result section's heading: a program's own title, or the circle's diagnostics.
const char* section_title(const std::string& section) {
  if (const auto kind = dsp::parse_program_kind(section)) return dsp::program_descriptor(*kind).title;
  return section == "diagnostics" ? "diagnostics" : "";
}

}  // namespace

std::string budget_text(const dsp::Run& run, const dsp::Analysis& analysis) {
  const dsp::ResolutionLimit* lim = dsp::resolution_limit(run.meta.program.kind);
  if (analysis.uncertainty_budget.empty() || !lim) return {};
  std::vector<std::string> keys{lim->limited};
  if (std::string(lim->headline) != lim->limited) keys.emplace_back(lim->headline);
  std::string o = "  uncertainty budget (each source alone, U with k = 2; share of the sum of squares):\n";
  char b[240];
  for (const std::string& key : keys) {
    const auto u = figure_u(analysis, key);
    if (!u) continue;
    std::snprintf(b, sizeof b, "    %s: U = %.2f %s\n", dsp::label_of_key(key).c_str(), *u,
                  dsp::unit_of_key(key).c_str());
    o += b;
    double sum2 = 0.0;
    for (const auto& [source, by_key] : analysis.uncertainty_budget)
      if (const auto it = by_key.find(key);
          it != by_key.end() && it->second.size() == 1 && std::isfinite(it->second[0]))
        sum2 += it->second[0] * it->second[0];
    for (const auto& [source, by_key] : analysis.uncertainty_budget) {
      const auto it = by_key.find(key);
      if (it == by_key.end() || it->second.size() != 1 || !std::isfinite(it->second[0])) continue;
      const double us = it->second[0];
      std::snprintf(b, sizeof b, "      %-44s %8.3f %s  %5.1f %%\n", dsp::uncertainty::error_source_words(source), us,
                    dsp::unit_of_key(key).c_str(), sum2 > 0.0 ? 100.0 * us * us / sum2 : 0.0);
      o += b;
    }
    const auto nb = analysis.noise_bound_k2.find(key);
    if (nb != analysis.noise_bound_k2.end() && nb->second.size() == 1) {
      std::snprintf(b, sizeof b, "      %-44s %8.3f %s\n", "noise bound (white noise, optimal smoother)", nb->second[0],
                    dsp::unit_of_key(key).c_str());
      o += b;
    }
  }
  return o;
}

namespace {

// Every figure with its U, section by section.
std::string figures_text(const dsp::Analysis& analysis) {
  std::string o;
  char b[320];
  std::string section;
  for (const dsp::FigureValue& f : dsp::figures_of(analysis)) {
    const std::string sec = f.key.substr(0, f.key.find('.'));
    if (sec != section) {
      section = sec;
      o += std::string("  ") + section_title(sec);
      if (sec == "circle" && analysis.circle)
        o += ", " + std::to_string(analysis.circle->revolutions) +
             (analysis.circle->arc_deg < 360.0 ? " arcs, " : " revolutions, ") + analysis.circle->direction;
      if (sec == "positioning" && analysis.positioning)
        o += ", axis " + analysis.positioning->axis + ", " + std::to_string(analysis.positioning->runs) + " runs";
      o += "\n";
    }
    const std::string unit = dsp::unit_of_key(f.key);
    if (!f.array) {
      if (const auto ne = analysis.not_evaluated.find(f.key); ne != analysis.not_evaluated.end()) {
        std::snprintf(b, sizeof b, "    %-34s not evaluated: %s\n", dsp::label_of_key(f.key).c_str(),
                      ne->second.c_str());
        o += b;
        continue;
      }
      const auto u = figure_u(analysis, f.key);
      std::snprintf(b, sizeof b, "    %-34s %s%s\n", dsp::label_of_key(f.key).c_str(),
                    value_with_u(f.values[0], u, unit).c_str(),
                    u && !dsp::uncertainty::resolved(f.values[0], *u) ? "   not resolved" : "");
      o += b;
      continue;
    }
    if (const auto ne = analysis.not_evaluated.find(f.key); ne != analysis.not_evaluated.end()) {
      o += "    " + dsp::label_of_key(f.key) + ": not evaluated: " + ne->second + "\n";
      continue;
    }
    std::string line = "    " + dsp::label_of_key(f.key) + " (" + unit + "):";
    for (std::size_t i = 0; i < f.values.size() && i < 24; ++i) {
      const auto u = figure_u(analysis, f.key, i);
      char e[80];
      if (u)
        std::snprintf(e, sizeof e, " %.2f±%.2f%s", f.values[i], *u,
                      dsp::uncertainty::resolved(f.values[i], *u) ? "" : "*");
      else
        std::snprintf(e, sizeof e, " %.2f", f.values[i]);
      line += e;
      if (f.columns > 1 && i % static_cast<std::size_t>(f.columns) != static_cast<std::size_t>(f.columns - 1))
        line += ",";
      else if (f.columns > 1)
        line += ";";
    }
    if (f.values.size() > 24) line += " …";
    o += line + "\n";
  }
  return o;
}

// U of the figure the test must resolve against its noise bound.
std::string noise_bound_text(const dsp::Run& run, const dsp::Analysis& analysis) {
  std::string o;
  char b[320];
  if (const dsp::ResolutionLimit* lim = dsp::resolution_limit(run.meta.program.kind)) {
    const auto u = figure_u(analysis, lim->limited);
    const auto nb = analysis.noise_bound_k2.find(lim->limited);
    if (u && nb != analysis.noise_bound_k2.end() && nb->second.size() == 1 && nb->second[0] > 0.0) {
      std::snprintf(b, sizeof b,
                    "  noise bound (the white noise measured at rest, the optimal smoother, these supports): U(%s) = "
                    "%.2f µm is %.2f × its bound %.2f µm\n",
                    lim->limited_name, *u, *u / nb->second[0], nb->second[0]);
      o += b;
    }
  }
  return o;
}

// The verdict, its reasons and the ISO 14253-1 decisions.
std::string verdict_text(const dsp::Analysis& analysis) {
  std::string o;
  char b[320];
  o += "  verdict: " +
       std::string(analysis.verdict == dsp::Verdict::not_measurable ? "NOT MEASURABLE"
                   : analysis.verdict == dsp::Verdict::degraded     ? "DEGRADED"
                                                                    : "ok") +
       "\n";
  for (const auto& r : analysis.verdict_reasons) o += "    - " + r + "\n";
  if (analysis.conformance) {
    o += std::string("  against the tolerances (ISO 14253-1, U with k = 2): ") +
         dsp::conformance_words(analysis.conformance->overall) + "\n";
    for (const auto& f : analysis.conformance->figures) {
      char u[32] = "unknown";
      if (std::isfinite(f.u_k2)) std::snprintf(u, sizeof u, "%.2f", f.u_k2);
      std::snprintf(b, sizeof b, "    %-40s %.2f ± %s against %.2f: %s\n", f.name.c_str(), f.magnitude, u, f.tolerance,
                    dsp::conformance_words(f.decision));
      o += b;
    }
    if (analysis.conformance->figures.empty()) o += "    (no toleranced figure in this test)\n";
  }
  return o;
}

}  // namespace

std::string summary_text(const dsp::Run& run, const dsp::Analysis& analysis) {
  std::string o;
  char b[320];
  std::snprintf(b, sizeof b, "run %s (%s, %zu samples at %.0f Hz)\n", run.meta.id.c_str(),
                dsp::program_kind_name(run.meta.program.kind), run.frame_count(), run.meta.acquisition.fs_hz);
  o += b;
  o += "  sensor model: " + sensor_model_text(analysis) + "\n";
  o += figures_text(analysis);
  if (analysis.circle && !analysis.circle->circular_hysteresis_H_um)
    o += "    circular hysteresis H              n/a (needs both directions)\n";
  if (analysis.circle_accuracy_rms_um) {
    std::snprintf(b, sizeof b, "  against the reference: %.2f µm RMS of (measured − reference) radius deviation\n",
                  *analysis.circle_accuracy_rms_um);
    o += b;
  }
  if (!analysis.uncertainty_note.empty())
    o += "  uncertainty: " + analysis.uncertainty_note +
         (analysis.uncertainty_k2.empty() ? "" : "; * not resolved (|value| <= U)") + "\n";
  o += budget_text(run, analysis);
  o += noise_bound_text(run, analysis);
  o += verdict_text(analysis);
  bool header = false;
  for (const dsp::Flag& f : analysis.flags) {
    if (!header) o += "  flags:\n", header = true;
    o += std::string("    [") + dsp::severity_name(dsp::severity(f)) + "] " + dsp::flag_text(f) + "\n";
  }
  return o;
}

}  // namespace eical::tools
