#include "tools/report/run_report.hpp"

#include "drivers/results/software_version.hpp"
#include "dsp/analysis/program_descriptor.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/float_limits.hpp"

#include "dsp/core/key_unit.hpp"
#include "tools/figure_text.hpp"
#include "tools/report/html.hpp"
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace eical::tools::report {
namespace fs = std::filesystem;

std::string fmt(const char* format, double v) {
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

std::pair<std::string, std::string> plane_axis_names(const std::string& plane) {
  if (plane == "zx") return {"Z", "X"};
  if (plane == "yz") return {"Y", "Z"};
  return {"X", "Y"};
}

void CsvFiles::write(const std::string& name, const std::vector<std::string>& header,
                     const std::vector<std::vector<double>>& cols) {
  const fs::path file = dir_ / name;
  std::ofstream os(file, std::ios::trunc);
  if (!os) throw std::runtime_error(file.string() + ": cannot write");
  for (std::size_t c = 0; c < header.size(); ++c) os << (c ? "," : "") << header[c];
  os << "\n";
  const std::size_t n = cols.empty() ? 0 : cols[0].size();
  const std::size_t q = (n + kMaxRows - 1) / kMaxRows;
  thinned_ |= q > 1;
  char buf[32];
  for (std::size_t i = 0; i < n; i += std::max<std::size_t>(1, q)) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      std::snprintf(buf, sizeof buf, "%.6f", i < cols[c].size() ? cols[c][i] : 0.0);
      os << (c ? "," : "") << buf;
    }
    os << "\n";
  }
  if (!os.flush()) throw std::runtime_error(file.string() + ": write failed");
  names_.push_back(name);
}

std::optional<double> FigureRows::value(const std::string& key, std::size_t i) const {
  const dsp::FigureValue* f = dsp::find_figure(figs_, key);
  if (!f || i >= f->values.size() || !std::isfinite(f->values[i])) return std::nullopt;
  return f->values[i];
}

std::optional<double> FigureRows::u(const std::string& key, std::size_t i) const {
  const auto it = a_.uncertainty_k2.find(key);
  if (it == a_.uncertainty_k2.end() || i >= it->second.size() || !std::isfinite(it->second[i])) return std::nullopt;
  return it->second[i];
}

Figure FigureRows::row(const std::string& key, std::string label, std::string unit, int decimals, std::string note,
                       double scale) const {
  Figure f{std::move(label), value(key), std::move(unit), decimals, std::move(note), u(key)};
  if (f.value) *f.value *= scale;
  if (f.u) *f.u *= scale;
  return f;
}

namespace {

// One line naming the program the way a calibration engineer would.
std::string program_line(const dsp::Program& p) {
  const auto [na, nb] = plane_axis_names(p.plane);
  if (p.kind == dsp::ProgramKind::circle) {
    std::string s = "circular test R " + fmt("%g", p.radius_mm) + " mm, F " + fmt("%g", p.feed_mm_min) + " mm/min, " +
                    na + nb + " plane, ";
    s += p.direction == "both" ? "both directions" : p.direction == "cw" ? "clockwise" : "counter-clockwise";
    if (p.arc_deg < 360.0) s += ", " + fmt("%g", p.arc_deg) + "° partial arc";
    return s;
  }
  if (p.kind == dsp::ProgramKind::positioning || p.kind == dsp::ProgramKind::step) {
    std::string s = (p.kind == dsp::ProgramKind::step ? "step response, axis " : "ISO 230-2 positioning, axis ") +
                    p.axis + ", targets";
    for (std::size_t i = 0; i < p.targets_mm.size() && i < 12; ++i) s += (i ? ", " : " ") + fmt("%g", p.targets_mm[i]);
    if (p.targets_mm.size() > 12) s += ", …";
    return s + " mm, " + std::to_string(p.runs) + " runs, F " + fmt("%g", p.feed_mm_min) + " mm/min";
  }
  if (p.kind == dsp::ProgramKind::rectangle)
    return "rectangle " + fmt("%g", p.size_mm[0]) + " × " + fmt("%g", p.size_mm[1]) + " mm in " + na + nb + ", F " +
           fmt("%g", p.feed_mm_min) + " mm/min";
  if (p.kind == dsp::ProgramKind::freeform)
    return "free-form path (G-code of the run), F " + fmt("%g", p.feed_mm_min) + " mm/min";
  return dsp::program_kind_name(p.kind) + std::string(" program");
}

// The headline figures' U beside their noise bound and, when the analysis has one, the
// budget: each source of the error alone.
void uncertainty_section(const dsp::Analysis& a, Page& page) {
  const dsp::ResolutionLimit* lim = dsp::resolution_limit(a.program_kind);
  if (!lim || a.uncertainty_k2.empty()) return;
  std::vector<std::string> keys{lim->limited};
  if (std::string(lim->headline) != lim->limited) keys.emplace_back(lim->headline);
  Section s;
  s.heading = "Uncertainty";
  s.lead = "Where U comes from, and how far it is from what the physics of this test allows.";
  std::vector<std::string> header{"source"};
  for (const auto& k : keys) header.push_back(dsp::label_of_key(k) + " (" + dsp::unit_of_key(k) + ")");
  Grid g{"U (k = 2) of each source alone, and of all together", header, {}};
  auto row = [&](const std::string& name, const std::map<std::string, std::vector<double>>& by_key) {
    std::vector<std::string> r{name};
    for (const auto& k : keys) {
      const auto it = by_key.find(k);
      r.push_back(it != by_key.end() && it->second.size() == 1 && std::isfinite(it->second[0])
                      ? fmt("%.3f", it->second[0])
                      : "-");
    }
    g.rows.push_back(std::move(r));
  };
  for (const auto& [source, by_key] : a.uncertainty_budget) row(dsp::uncertainty::error_source_words(source), by_key);
  row("all sources (U)", a.uncertainty_k2);
  row("noise bound: white noise only, optimal smoother", a.noise_bound_k2);
  s.grids.push_back(std::move(g));
  if (a.uncertainty_budget.empty())
    s.notes.push_back(
        "eical analyze --budget adds each source's own U (integration noise, sensor scale and timing, "
        "temperature, PSD strip offsets and nonlinearity).");
  s.notes.push_back(
      "The noise bound is the same evaluation of the ideal path with only the white noise measured at "
      "rest, fused by the smoother that is optimal for it over this run's supports: what this test "
      "could reach with a perfect sensor model.");
  page.sections.push_back(std::move(s));
}

void measurement_section(const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  const auto& m = a.measurement;
  Section p;
  p.heading = "Measurement";
  p.lead = "How the relative path head − table was obtained from the two accelerometers.";
  p.tables.push_back(
      {"Supports",
       {{"Rest window before the motion", static_cast<double>(m.rest_window_samples) / m.fs_hz, "s", 3,
         "bias reference (M101 → motion)"},
        {"ZUPT window after the motion", static_cast<double>(m.zupt_window_samples) / m.fs_hz, "s", 3, ""},
        {"Velocity error removed by ZUPT, x", m.zupt_velocity_error_mm_s.x() * 1000.0, "µm/s", 2, ""},
        {"Velocity error removed by ZUPT, y", m.zupt_velocity_error_mm_s.y() * 1000.0, "µm/s", 2, ""},
        {"Velocity error removed by ZUPT, z", m.zupt_velocity_error_mm_s.z() * 1000.0, "µm/s", 2, ""}}});
  p.notes.push_back(
      "Pipeline: " + std::string(a.sensor_model == "datasheet" ? "data-sheet" : "calibrated (" + a.sensor_model + ")") +
      " static compensation, rest-window bias, trapezoid double integration, " +
      (a.dynamic == dsp::DynamicComp::none ? "no" : "two-stage") +
      " dynamic compensation (6-38) and the DAQ group delay, ZUPT at the standstills" +
      (a.nbs ? ", NBS on held axes" : "") + ", CUPT at the PSD strips, Rauch–Tung–Striebel smoother.");
  if (!a.uncertainty_note.empty())
    p.notes.push_back(
        "Uncertainty (every ± in this report): " + a.uncertainty_note +
        ". A figure is resolved when its magnitude exceeds U; one that is not is marked \"not resolved\": its "
        "magnitude is then at most |value| + U.");
  page.sections.push_back(std::move(p));
  uncertainty_section(a, page);
  std::vector<std::vector<double>> cols(7);
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    cols[0].push_back(static_cast<double>(m.sample_index[i]) / m.fs_hz);
    for (int k = 0; k < 3; ++k)
      cols[1 + static_cast<std::size_t>(k)].push_back(m.cmd_mm[i][k]),
          cols[4 + static_cast<std::size_t>(k)].push_back(m.pos_mm[i][k]);
  }
  csv.write(
      "trace_measurement.csv",
      {"t_s", "setpoint_x_mm", "setpoint_y_mm", "setpoint_z_mm", "measured_x_mm", "measured_y_mm", "measured_z_mm"},
      cols);
}

// Case temperatures over the run: "table 22.10–22.11 °C, head 24.29 °C".
std::string temperatures(const dsp::Run& run) {
  std::string out;
  const char* names[2] = {"table", "head"};
  for (int s = 0; s < 2; ++s) {
    double lo = kInf, hi = -kInf;
    for (const auto& f : run.frames)
      if (!(f.flags & dsp::frame_flag::temp_missing) && std::isfinite(f.temp_c[s]))
        lo = std::min(lo, static_cast<double>(f.temp_c[s])), hi = std::max(hi, static_cast<double>(f.temp_c[s]));
    if (!std::isfinite(lo)) continue;
    out += std::string(out.empty() ? "" : ", ") + names[s] + " " + fmt("%.2f", lo) +
           (hi - lo >= 0.005 ? "–" + fmt("%.2f", hi) : "") + " °C";
  }
  return out.empty() ? "not recorded" : out;
}

std::string settings(const dsp::Run& run, const dsp::Analysis& a) {
  std::string s = fmt("%.0f Hz", run.meta.acquisition.fs_hz) + ", " + std::to_string(run.frames.size()) + " samples, " +
                  std::to_string(run.meta.psd.size()) + " PSD strip" + (run.meta.psd.size() == 1 ? "" : "s") +
                  ", sensor model " +
                  (a.sensor_model == "datasheet" ? std::string("data sheet") : "identified (" + a.sensor_model + ")") +
                  ", dynamic compensation " + (a.dynamic == dsp::DynamicComp::none ? "off" : "two-stage") +
                  (a.coriolis ? ", Earth rate corrected" : "");
  return s;
}

// What the result rests on: the sensors, the sensor model (data sheet or the identified
// calibration with its U), the strips, the reference, the software.
std::vector<std::pair<std::string, std::string>> traceability(const dsp::Run& run, const dsp::Analysis& a,
                                                              const ReportOptions& options) {
  std::vector<std::pair<std::string, std::string>> t;
  const char* where[2] = {"table", "head"};
  for (int s = 0; s < 2; ++s) {
    const auto& spec = run.meta.sensors[s];
    t.emplace_back(std::string("sensor, ") + where[s], spec.model + fmt(", noise %.2f µg/√Hz", spec.noise_ug_per_rthz) +
                                                           fmt(", f0 %.0f Hz", spec.f0_hz) +
                                                           " (serial: not recorded in the run)");
  }
  t.emplace_back("sensor model", !options.calibration.empty()    ? options.calibration
                                 : a.sensor_model == "datasheet" ? "the data sheet's, with its tolerances as U"
                                                                 : "identified (" + a.sensor_model + ")");
  std::string strips;
  for (const auto& p : run.meta.psd)
    strips += std::string(strips.empty() ? "" : "; ") + p.measures + fmt(" at (%.3f", p.center_mm[0]) +
              fmt(", %.3f) mm", p.center_mm[1]) + fmt(", %.0f mm", p.length_mm);
  t.emplace_back("PSD strips", strips.empty() ? "none"
                                              : strips +
                                                    " (position calibration: run.toml [[psd]]; nonlinearity within "
                                                    "the data sheet's ±0.01 % of the strip's half length, in U)");
  if (run.meta.reference) t.emplace_back("reference", run.meta.reference->kind);
  // ISO 230-3: the sensors' case temperatures are all the run records; the machine's and
  // the air's are not, and nothing is corrected to 20 °C.
  t.emplace_back("thermal", "sensor cases " + temperatures(run) +
                                "; machine, air and part temperatures not recorded; no correction to 20 °C (ISO "
                                "230-3 drift not separated): the figures hold at the temperatures of the run");
  t.emplace_back("recorded",
                 run.meta.created.empty() ? "not recorded (a simulated run has no recording date)" : run.meta.created);
  t.emplace_back("software", std::string(drivers::software_version()));
  return t;
}

}  // namespace

fs::path write_run_report(const dsp::Run& run, const dsp::Analysis& analysis, const fs::path& dir,
                          const ReportOptions& options) {
  fs::create_directories(dir);
  CsvFiles csv(dir);
  Page page;
  const auto& p = run.meta.program;
  page.title = dsp::program_descriptor(p.kind).report_title;
  page.run_id = run.meta.id;
  page.program = program_line(p);
  const Tolerances tol = options.tolerances.value_or(Tolerances{});
  const std::string machine = tol.machine.empty() ? run.meta.machine.name : tol.machine;
  const std::string serial = !options.serial.empty() ? options.serial : tol.serial;
  const std::string op = !options.operator_name.empty() ? options.operator_name : tol.operator_name;
  page.context = {{"machine", machine + (serial.empty() ? ", serial not given" : ", serial " + serial)},
                  {"operator", op.empty() ? "not given" : op},
                  {"run recorded", run.meta.created.empty() ? "not recorded" : run.meta.created},
                  {"temperatures", temperatures(run)},
                  {"software", std::string(drivers::software_version())},
                  {"test settings", settings(run, analysis)},
                  {"sensors", run.meta.sensors[0].model + " (table), " + run.meta.sensors[1].model + " (head)"}};
  if (run.meta.reference) page.context.emplace_back("reference", run.meta.reference->kind);
  for (const dsp::Flag& f : analysis.flags)
    page.flags.push_back({dsp::flag_text(f), dsp::severity_name(dsp::severity(f))});
  page.verdict = dsp::verdict_name(analysis.verdict);
  page.verdict_reasons = analysis.verdict_reasons;
  if (options.tolerances) {
    // The analysis' decision when it was made with the tolerances (analyze --tolerances),
    // else made here from the same rule, and the verdict judged again with it: one story in
    // the banner, the table and the JSON.
    const dsp::ConformanceResult c =
        analysis.conformance ? *analysis.conformance : dsp::decide_conformance(analysis, figure_tolerances(tol));
    if (!analysis.conformance) {
      dsp::Analysis judged = analysis;
      judged.conformance = c;
      dsp::judge(p, judged);
      page.verdict = dsp::verdict_name(judged.verdict);
      page.verdict_reasons = judged.verdict_reasons;
    }
    page.conformance = dsp::conformance_words(c.overall);
    Grid g{std::string("Against the tolerances (ISO 14253-1 with U, k = 2): ") + dsp::conformance_words(c.overall),
           {"figure", "measured (µm)", "U (µm)", "tolerance (µm)", "decision"},
           {}};
    for (const auto& d : c.figures)
      g.rows.push_back({d.name, fmt("%.2f", d.magnitude), std::isfinite(d.u_k2) ? fmt("%.2f", d.u_k2) : "unknown",
                        fmt("%.2f", d.tolerance), dsp::conformance_words(d.decision)});
    if (g.rows.empty()) g.rows.push_back({"(no toleranced figure in this test)", "", "", "", ""});
    page.summary.push_back(g);
  }
  page.traceability = traceability(run, analysis, options);
  page.approval = {{"performed by", op}, {"approved by", ""}, {"date", ""}, {"signature", ""}, {"remarks", ""}};
  program_sections(run, analysis, page, csv);
  measurement_section(analysis, page, csv);
  page.files = csv.names();
  if (csv.thinned())
    page.files_note = "Long traces are thinned to at most " + std::to_string(CsvFiles::kMaxRows) +
                      " rows per file (the run holds every sample).";
  const fs::path file = dir / "report.html";
  write_html(page, file);
  return file;
}

}  // namespace eical::tools::report
