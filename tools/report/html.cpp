#include "tools/report/html.hpp"

#include "tools/report/svg.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace eical::tools::report {
namespace {

// Print-friendly, quiet typography: one sans-serif family, tabular figures in tables,
// a dark header band with the run id and the program.
constexpr const char* kStyle = R"(
*{box-sizing:border-box}
body{font-family:"Inter","Segoe UI","Helvetica Neue","DejaVu Sans",Arial,sans-serif;margin:0;color:#1d2330;background:#f4f6f9;font-size:14px;line-height:1.45}
header{background:#17233b;color:#fff;padding:22px 40px 18px}
header .brand{font-size:12px;letter-spacing:.12em;text-transform:uppercase;color:#9fb3d9}
header h1{font-size:24px;font-weight:600;margin:4px 0 6px}
header .prog{font-size:15px;color:#dfe7f5}
header .runid{font-family:"DejaVu Sans Mono",Consolas,monospace;font-size:13px;color:#fff;background:#2b3b5c;padding:2px 8px;border-radius:3px}
dl.ctx{display:flex;flex-wrap:wrap;gap:4px 28px;margin:12px 0 0;font-size:12px;color:#b8c6e0}
dl.ctx dt{display:inline;color:#8ea2c8}dl.ctx dd{display:inline;margin:0 0 0 6px;color:#e9eef8}
main{max-width:1220px;margin:0 auto;padding:18px 40px 40px}
.warn{background:#fff6e5;border-left:4px solid #e59400;padding:6px 12px;margin:6px 0;font-size:13px}
section{background:#fff;border:1px solid #dde2ea;border-radius:6px;padding:18px 22px;margin:18px 0}
h2{font-size:18px;font-weight:600;margin:0 0 2px}
p.lead{color:#5a6478;margin:0 0 12px}
.row{display:flex;flex-wrap:wrap;gap:22px;align-items:flex-start}
.plots{display:flex;flex-direction:column;gap:10px}
.tables{display:flex;flex-direction:column;gap:14px;flex:1;min-width:330px}
table{border-collapse:collapse;width:100%;font-size:13px}
caption{text-align:left;font-weight:600;font-size:12px;letter-spacing:.06em;text-transform:uppercase;color:#5a6478;padding:0 0 4px}
th{text-align:right;font-weight:600;color:#5a6478;border-bottom:1px solid #c9d0db;padding:3px 8px}
th:first-child{text-align:left}
td{padding:3px 8px;border-bottom:1px solid #eef0f4}
td.v{text-align:right;font-variant-numeric:tabular-nums;font-weight:600;white-space:nowrap}
td.u{color:#5a6478;white-space:nowrap}
td.n{color:#6b7385;font-size:12px}
td.c{text-align:right;font-variant-numeric:tabular-nums}
.na{color:#a33;font-weight:500}
p.note{color:#3b4456;max-width:70em;font-size:13px;margin:10px 0 0}
svg.plot{background:#fff;border:1px solid #e3e7ee;border-radius:4px}
footer{color:#6b7385;font-size:12px;margin-top:10px}
footer a{color:#1f5fbf}
.flag{padding:6px 12px;margin:6px 0;font-size:13px;border-left:4px solid}
.flag b{display:inline-block;min-width:5.5em;text-transform:uppercase;font-size:11px;letter-spacing:.06em}
.flag.critical{background:#fdecea;border-color:#c0392b;color:#7b1d14}
.flag.warning{background:#fff6e5;border-color:#e59400}
.flag.note{background:#f1f3f6;border-color:#a8b0bd;color:#4a5366}
.verdict{padding:10px 16px;margin:14px 0 6px;border-radius:6px;font-size:15px}
.verdict b{font-size:16px;letter-spacing:.04em}
.verdict ul{margin:4px 0 0;padding-left:20px;font-size:13px}
.verdict.ok{background:#e8f5ee;border:1px solid #7cc49a}
.verdict.degraded{background:#fff6e5;border:1px solid #e5b14d}
.verdict.not_measurable{background:#fdecea;border:1px solid #d77a70}
td.v .pm{font-weight:400;color:#5a6478}
td.n .nr,.nr{color:#a35a00;font-style:italic}
td.pass{color:#1e8449;font-weight:600;text-align:right}
td.fail{color:#c0392b;font-weight:600;text-align:right}
td.undecided{color:#a35a00;font-weight:600;text-align:right}
table.sign{border-collapse:collapse;width:100%;max-width:640px}
table.sign th{text-align:left;font-weight:500;width:30%;padding:14px 8px 4px 0}
table.sign td{border-bottom:1px solid #333;padding:14px 8px 4px}
section.approval{break-inside:avoid;page-break-inside:avoid}
@page{size:A4;margin:12mm 11mm}
@media print{
 body{background:#fff;font-size:9.5pt}
 header{padding:10px 14px;-webkit-print-color-adjust:exact;print-color-adjust:exact}
 .flag,.verdict,td.pass,td.fail{-webkit-print-color-adjust:exact;print-color-adjust:exact}
 main{max-width:none;padding:0 2mm}
 section{border:none;border-top:1px solid #c9d0db;border-radius:0;padding:8px 0;margin:8px 0;break-inside:auto}
 .row{display:block}
 .plots{display:block}
 svg.plot{display:block;width:100%;max-width:100%;height:auto;break-inside:avoid;border:none}
 svg.polar{display:inline-block;vertical-align:top;width:49.5%}
 table{break-inside:auto;font-size:9pt}
 tr{break-inside:avoid}
 .tables{min-width:0}
 h2{break-after:avoid}
 footer a{color:#1d2330;text-decoration:none}
}
)";

std::string format_value(const Figure& f) {
  if (!f.value || !std::isfinite(*f.value)) return "<span class=\"na\">n/a</span>";
  char buf[96];
  // No "-0.00": a value that rounds to zero is shown as zero.
  const double v = std::abs(*f.value) < 0.5 * std::pow(10.0, -f.decimals) ? 0.0 : *f.value;
  std::snprintf(buf, sizeof buf, "%.*f", f.decimals, v);
  std::string out = buf;
  if (f.u && std::isfinite(*f.u)) {
    std::snprintf(buf, sizeof buf, " <span class=\"pm\">± %.*f</span>", f.decimals, *f.u);
    out += buf;
  }
  return out;
}

bool not_resolved(const Figure& f) {
  return f.value && f.u && std::isfinite(*f.value) && std::isfinite(*f.u) && !(std::abs(*f.value) > *f.u);
}

std::string cell_class(const std::string& text) {
  // The ISO 14253-1 decisions (dsp::conformance_words) coloured as such.
  if (text == "conformance proven") return "pass";
  if (text == "non-conformance proven") return "fail";
  if (text == "undecided") return text;
  return "c";
}

const char* verdict_word(const std::string& v) {
  if (v == "not_measurable") return "NOT MEASURABLE";
  if (v == "degraded") return "DEGRADED";
  return "OK";
}

std::string grid_html(const Grid& g) {
  std::string out = "<table style=\"margin-top:14px\">";
  if (!g.caption.empty()) out += "<caption>" + xml_escape(g.caption) + "</caption>";
  out += "<tr>";
  for (const auto& h : g.header) out += "<th>" + xml_escape(h) + "</th>";
  out += "</tr>\n";
  for (const auto& r : g.rows) {
    out += "<tr>";
    for (std::size_t i = 0; i < r.size(); ++i)
      out += (i ? "<td class=\"" + cell_class(r[i]) + "\">" : "<td>") + xml_escape(r[i]) + "</td>";
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

// What the result rests on, and the block a signer fills in by hand.
std::string signing_html(const Page& page) {
  std::string out;
  if (!page.traceability.empty()) {
    out += "<section class=\"trace\"><h2>Traceability</h2><table class=\"grid\">";
    for (const auto& [k, v] : page.traceability)
      out += "<tr><th>" + xml_escape(k) + "</th><td>" + xml_escape(v) + "</td></tr>";
    out += "</table></section>\n";
  }
  if (!page.approval.empty()) {
    // Printed and signed by hand: empty fields are lines to write on.
    out += "<section class=\"approval\"><h2>Approval</h2><table class=\"sign\">";
    for (const auto& [k, v] : page.approval)
      out += "<tr><th>" + xml_escape(k) + "</th><td>" + (v.empty() ? "&nbsp;" : xml_escape(v)) + "</td></tr>";
    out += "</table></section>\n";
  }
  return out;
}

}  // namespace

std::string render_html(const Page& page) {
  std::string out;
  out.reserve(256 * 1024);
  out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" +
         xml_escape(page.title + " — " + page.run_id) + "</title>\n<style>" + kStyle +
         "</style></head><body>\n<header>\n<div class=\"brand\">eical · inertial machine-tool calibration</div>\n";
  out += "<h1>" + xml_escape(page.title) + "</h1>\n";
  out += "<div class=\"prog\">" + xml_escape(page.subject_label) + " <span class=\"runid\">" + xml_escape(page.run_id) +
         "</span> &nbsp;·&nbsp; " + xml_escape(page.program) + "</div>\n";
  if (!page.context.empty()) {
    out += "<dl class=\"ctx\">";
    for (const auto& [k, v] : page.context)
      out += "<div><dt>" + xml_escape(k) + "</dt><dd>" + xml_escape(v) + "</dd></div>";
    out += "</dl>\n";
  }
  out += "</header>\n<main>\n";
  if (!page.verdict.empty()) {
    out += "<div class=\"verdict " + xml_escape(page.verdict) + "\">Verdict: <b>" + verdict_word(page.verdict) + "</b>";
    // The verdict judges the measurement; the tolerances are a decision of their own, and
    // a reader must not take an OK measurement for a machine in tolerance.
    if (!page.conformance.empty())
      out += " (the measurement) &nbsp;·&nbsp; against the tolerances: <b>" + xml_escape(page.conformance) + "</b>";
    if (!page.verdict_reasons.empty()) {
      out += "<ul>";
      for (const auto& r : page.verdict_reasons) out += "<li>" + xml_escape(r) + "</li>";
      out += "</ul>";
    }
    out += "</div>\n";
  }
  for (const auto& g : page.summary) out += "<section>" + grid_html(g) + "</section>\n";
  for (const char* sev : {"critical", "warning", "note"})
    for (const auto& f : page.flags)
      if (f.severity == sev)
        out += std::string("<div class=\"flag ") + sev + "\"><b>" + sev + "</b> " + xml_escape(f.text) + "</div>\n";
  for (const auto& w : page.warnings) out += "<div class=\"warn\">" + xml_escape(w) + "</div>\n";
  for (const auto& s : page.sections) {
    out += "<section><h2>" + xml_escape(s.heading) + "</h2>\n";
    if (!s.lead.empty()) out += "<p class=\"lead\">" + xml_escape(s.lead) + "</p>\n";
    out += "<div class=\"row\">\n";
    if (!s.svgs.empty()) {
      out += "<div class=\"plots\">";
      for (const auto& svg : s.svgs) out += svg;
      out += "</div>\n";
    }
    if (!s.tables.empty()) {
      out += "<div class=\"tables\">";
      for (const auto& t : s.tables) {
        out += "<table>";
        if (!t.caption.empty()) out += "<caption>" + xml_escape(t.caption) + "</caption>";
        for (const auto& f : t.rows)
          out += "<tr><td>" + xml_escape(f.label) + "</td><td class=\"v\">" + format_value(f) +
                 "</td><td class=\"u\">" + xml_escape(f.unit) + "</td><td class=\"n\">" +
                 (not_resolved(f) ? "<span class=\"nr\">not resolved</span>" + std::string(f.note.empty() ? "" : "; ")
                                  : "") +
                 xml_escape(f.note) + "</td></tr>\n";
        out += "</table>\n";
      }
      out += "</div>\n";
    }
    out += "</div>\n";
    for (const auto& g : s.grids) out += grid_html(g);
    for (const auto& n : s.notes) out += "<p class=\"note\">" + xml_escape(n) + "</p>\n";
    out += "</section>\n";
  }
  out += signing_html(page);
  if (!page.files.empty()) {
    out += "<footer>Every trace behind the plots, as CSV: ";
    for (std::size_t i = 0; i < page.files.size(); ++i)
      out += std::string(i ? ", " : "") + "<a href=\"" + xml_escape(page.files[i]) + "\">" + xml_escape(page.files[i]) +
             "</a>";
    out += ". Machine-readable figures: <a href=\"result.json\">result.json</a> (eical-result/1).";
    if (!page.files_note.empty()) out += " " + xml_escape(page.files_note);
    out += "</footer>\n";
  }
  out += "</main></body></html>\n";
  return out;
}

void write_html(const Page& page, const std::filesystem::path& file) {
  const std::string text = render_html(page);
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp.string() + ": cannot create: " + std::strerror(errno));
    os.write(text.data(), static_cast<std::streamsize>(text.size()));
    os.flush();
    if (!os) throw std::runtime_error(tmp.string() + ": write failed: " + std::strerror(errno));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw std::runtime_error(file.string() + ": cannot rename report into place: " + ec.message());
  }
}

}  // namespace eical::tools::report
