#pragma once
// Self-contained HTML report pages: inline CSS, inline SVG, no scripts, no network.
// A page is a title, a line of context and sections; each section shows a table of
// figures (value + unit + optional note) beside its plots, the way ballbar software lays
// out a diagnostics page.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace eical::tools::report {

struct Figure {
  std::string label;
  std::optional<double> value;  // nullopt = could not be determined (shown as "n/a")
  std::string unit;
  int decimals = 1;
  std::string note;  // e.g. the reason a figure is missing or a tolerance
};

struct Section {
  std::string heading;
  std::vector<Figure> figures;
  std::vector<std::string> svgs;  // complete <svg> elements from svg.hpp
  std::vector<std::string> notes;  // plain text paragraphs
};

struct Page {
  std::string title;
  std::string subtitle;  // run id, program, date
  std::vector<std::string> warnings;  // quality flags: shown at the top, never hidden
  std::vector<Section> sections;
};

std::string render_html(const Page& page);

// Writes atomically (temporary file + rename) so a reader never sees half a report.
void write_html(const Page& page, const std::filesystem::path& file);

}  // namespace eical::tools::report
