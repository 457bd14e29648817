#include "tools/run_files.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/uncertainty/resolved.hpp"
#include "tools/exit_codes.hpp"
#include "tools/figure_text.hpp"

#include <cerrno>
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

int verdict_exit_code(const std::string& verdict) {
  if (verdict == "not_measurable") return kExitNotMeasurable;
  if (verdict == "degraded") return kExitDegraded;
  return kExitOk;
}

namespace {

const char* section_title(const std::string& section) {
  if (section == "circle") return "circular test (ISO 230-4)";
  if (section == "diagnostics") return "diagnostics";
  if (section == "positioning") return "positioning (ISO 230-2)";
  if (section == "step") return "step response";
  if (section == "rectangle") return "rectangle";
  if (section == "freeform") return "free form";
  return "";
}

}  // namespace

std::string summary_text(const dsp::Run& run, const dsp::Analysis& analysis) {
  std::string o;
  char b[320];
  std::snprintf(b, sizeof b, "run %s (%s, %zu samples at %.0f Hz)\n", run.meta.id.c_str(),
                run.meta.program.kind.c_str(), run.frame_count(), run.meta.acquisition.fs_hz);
  o += b;
  o += "  sensor model: " + sensor_model_text(analysis) + "\n";
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
    const std::string unit = figure_unit(f.key);
    if (!f.array) {
      const auto u = figure_u(analysis, f.key);
      std::snprintf(b, sizeof b, "    %-34s %s%s\n", figure_label(f.key).c_str(),
                    value_with_u(f.values[0], u, unit).c_str(),
                    u && !dsp::uncertainty::resolved(f.values[0], *u) ? "   not resolved" : "");
      o += b;
      continue;
    }
    std::string line = "    " + figure_label(f.key) + " (" + unit + "):";
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
  o += "  verdict: " +
       std::string(analysis.verdict == "not_measurable" ? "NOT MEASURABLE"
                   : analysis.verdict == "degraded"     ? "DEGRADED"
                                                        : "ok") +
       "\n";
  for (const auto& r : analysis.verdict_reasons) o += "    - " + r + "\n";
  bool header = false;
  for (const auto& f : analysis.flags) {
    const auto s = dsp::flag_severity(f);
    if (!header) o += "  flags:\n", header = true;
    o += std::string("    [") + dsp::severity_name(s) + "] " + f + "\n";
  }
  return o;
}

}  // namespace eical::tools
