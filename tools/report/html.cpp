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

constexpr const char* kStyle = R"(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:2em auto;max-width:1100px;color:#1d2330;background:#fff}
h1{font-size:1.6em;margin:0 0 .2em}
.sub{color:#5a6478;margin-bottom:1.2em}
.warn{background:#fff4e0;border-left:4px solid #e59400;padding:.5em .8em;margin:.4em 0}
section{border-top:1px solid #d8dde6;padding-top:1em;margin-top:1.4em}
h2{font-size:1.2em;margin:0 0 .6em}
.row{display:flex;flex-wrap:wrap;gap:1.5em;align-items:flex-start}
table{border-collapse:collapse;min-width:300px}
td{padding:.25em .6em;border-bottom:1px solid #eef0f4}
td.v{text-align:right;font-variant-numeric:tabular-nums;font-weight:600}
td.n{color:#5a6478;font-size:.9em}
.na{color:#a33}
p.note{color:#3b4456;max-width:60em}
)";

std::string format_value(const Figure& f) {
  if (!f.value || !std::isfinite(*f.value)) return "<span class=\"na\">n/a</span>";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", f.decimals, *f.value);
  return buf;
}

}  // namespace

std::string render_html(const Page& page) {
  std::string out;
  out.reserve(64 * 1024);
  out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>";
  out += xml_escape(page.title);
  out += "</title>\n<style>";
  out += kStyle;
  out += "</style></head><body>\n<h1>" + xml_escape(page.title) + "</h1>\n";
  out += "<div class=\"sub\">" + xml_escape(page.subtitle) + "</div>\n";
  for (const auto& w : page.warnings) out += "<div class=\"warn\">" + xml_escape(w) + "</div>\n";
  for (const auto& s : page.sections) {
    out += "<section><h2>" + xml_escape(s.heading) + "</h2>\n<div class=\"row\">\n";
    if (!s.figures.empty()) {
      out += "<table>\n";
      for (const auto& f : s.figures) {
        out += "<tr><td>" + xml_escape(f.label) + "</td><td class=\"v\">" + format_value(f) +
               "</td><td>" + xml_escape(f.unit) + "</td><td class=\"n\">" + xml_escape(f.note) +
               "</td></tr>\n";
      }
      out += "</table>\n";
    }
    for (const auto& svg : s.svgs) out += "<div>" + svg + "</div>\n";
    out += "</div>\n";
    for (const auto& n : s.notes) out += "<p class=\"note\">" + xml_escape(n) + "</p>\n";
    out += "</section>\n";
  }
  out += "</body></html>\n";
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
