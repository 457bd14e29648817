#pragma once
// The report's sections, one file per program kind, and what they share: CSV writing
// (every trace behind a plot is written next to the report) and formatting helpers.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"
#include "tools/report/html.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace eical::tools::report {

// Collects the CSV files of one report: each call writes `dir/name` and records the name.
class CsvFiles {
 public:
  explicit CsvFiles(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // Columns of equal length; numbers with 6 decimals.
  void write(const std::string& name, const std::vector<std::string>& header, const std::vector<std::vector<double>>& cols);
  [[nodiscard]] const std::vector<std::string>& names() const { return names_; }

 private:
  std::filesystem::path dir_;
  std::vector<std::string> names_;
};

std::string fmt(const char* format, double v);
// "+X", "+Y", "+Z" for the plane's two axes (xy → X, Y; zx → Z, X; yz → Y, Z).
std::pair<std::string, std::string> plane_axis_names(const std::string& plane);

void circle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void positioning_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void step_sections(const dsp::Analysis& a, Page& page, CsvFiles& csv);
void rectangle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);
void freeform_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv);

}  // namespace eical::tools::report
