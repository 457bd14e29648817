#pragma once
// The report's sections, one file per program kind, and what they share: CSV writing
// (every trace behind a plot is written next to the report) and formatting helpers.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"
#include "dsp/core/run.hpp"
#include "tools/report/html.hpp"

#include <optional>

#include <filesystem>
#include <string>
#include <vector>

namespace eical::tools::report {

// Collects the CSV files of one report: each call writes `dir/name` and records the name.
class CsvFiles {
 public:
  explicit CsvFiles(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // Columns of equal length; numbers with 6 decimals. A trace longer than kMaxRows is
  // thinned to every q-th row (the run itself holds every sample): one test's CSV stays
  // a few MB, not the 180 MB a ballbar-size circle at 10 kHz would make.
  static constexpr std::size_t kMaxRows = 50000;
  void write(const std::string& name, const std::vector<std::string>& header,
             const std::vector<std::vector<double>>& cols);
  [[nodiscard]] bool thinned() const { return thinned_; }
  [[nodiscard]] const std::vector<std::string>& names() const { return names_; }

 private:
  std::filesystem::path dir_;
  std::vector<std::string> names_;
  bool thinned_ = false;
};

// Figures of an analysis by result key (dsp/analysis/figures.hpp) with their expanded
// uncertainty, as report rows.
class FigureRows {
 public:
  explicit FigureRows(const dsp::Analysis& a) : a_(a), figs_(dsp::figures_of(a)) {}
  [[nodiscard]] std::optional<double> value(const std::string& key, std::size_t i = 0) const;
  [[nodiscard]] std::optional<double> u(const std::string& key, std::size_t i = 0) const;
  // Value (n/a when absent) ± U; `scale` converts the unit (e.g. s → ms).
  [[nodiscard]] Figure row(const std::string& key, std::string label, std::string unit, int decimals,
                           std::string note = "", double scale = 1.0) const;

 private:
  const dsp::Analysis& a_;
  std::vector<dsp::FigureValue> figs_;
};

std::string fmt(const char* format, double v);
// "+X", "+Y", "+Z" for the plane's two axes (xy → X, Y; zx → Z, X; yz → Y, Z).
std::pair<std::string, std::string> plane_axis_names(const std::string& plane);

// Each program's sections of the report (one file each), nothing when its evaluation is
// missing; program_sections() calls the one of the run's kind.
void circle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void positioning_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void step_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void rectangle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void freeform_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void program_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);

}  // namespace eical::tools::report
