#pragma once
// Self-contained HTML report pages: inline CSS, inline SVG, no scripts, no network.
// A page is a header (title, run id, program, context), the quality flags, and sections;
// each section shows its plots with the tables of figures beside them, the way ballbar
// software lays out a diagnostics page, and notes on how the figures were obtained.
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
  std::string note;  // e.g. the reason a figure is missing or a convention
  std::optional<double> u =
      std::nullopt;  // expanded uncertainty (k = 2): shown as "value ± U", "not resolved" when |value| <= U
};

struct Table {
  std::string caption;
  std::vector<Figure> rows;
};

// A table of text cells (e.g. per corner, per target) with a header row.
struct Grid {
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Section {
  std::string heading;
  std::string lead;                // one line under the heading: what the test is
  std::vector<std::string> svgs;   // complete <svg> elements from svg.hpp (left)
  std::vector<Table> tables;       // beside the plots (right)
  std::vector<Grid> grids;         // below
  std::vector<std::string> notes;  // plain text paragraphs
};

// A quality flag with its severity: "critical" (the measurement is wrong or incomplete),
// "warning" (it limits the measurement) or "note" (why a figure is absent).
struct Flag {
  std::string text;
  std::string severity = "note";
};

struct Page {
  std::string title;
  std::string run_id;
  std::string subject_label = "Run";  // what run_id names in the header: "Run", "Figure", "Runs"
  std::string program;                // e.g. "circle R 10 mm, F 2500 mm/min, XY, both directions"
  std::vector<std::pair<std::string, std::string>> context;  // label → value under the header
  std::vector<std::string> warnings;                         // shown at the top, never hidden
  std::vector<Flag> flags;                                   // quality flags, critical first
  std::string verdict;                                       // "ok", "degraded", "not_measurable" (a banner when set)
  std::vector<std::string> verdict_reasons;
  // With tolerances: ISO 14253-1's decision for the whole run (conformance_words), said in
  // the banner beside the verdict so that the two are read as one story.
  std::string conformance;
  std::vector<Grid> summary;  // right under the banner (e.g. against the tolerances)
  std::vector<Section> sections;
  // Traceability (what the result rests on) and the approval block a signer fills in.
  std::vector<std::pair<std::string, std::string>> traceability;
  std::vector<std::pair<std::string, std::string>> approval;  // label → value ("" = a line to fill in)
  std::vector<std::string> files;                             // CSV files next to the report (linked at the end)
  std::string files_note;                                     // e.g. how the CSV traces were thinned
};

std::string render_html(const Page& page);

// Writes atomically (temporary file + rename) so a reader never sees half a report.
void write_html(const Page& page, const std::filesystem::path& file);

}  // namespace eical::tools::report
