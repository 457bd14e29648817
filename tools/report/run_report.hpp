#pragma once
// The report of one analysed run: a self-contained HTML page (report.html) with the
// figures and plots a metrology engineer expects for the program kind, and every trace
// behind the plots as CSV next to it.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"

#include "tools/report/tolerances.hpp"

#include <filesystem>
#include <optional>

namespace eical::tools::report {

struct ReportOptions {
  std::optional<Tolerances> tolerances;  // pass/fail and the header's machine, serial, operator
  std::string operator_name, serial;     // override the tolerance file's header
  // The sensor model the analysis used, for the traceability block: "data sheet" or the
  // calibration file, the run it was identified from and its U (cmd_report says it).
  std::string calibration;
};

// Writes <dir>/report.html and <dir>/trace_*.csv; returns the path of the HTML file.
std::filesystem::path write_run_report(const dsp::Run& run, const dsp::Analysis& analysis,
                                       const std::filesystem::path& dir, const ReportOptions& options = {});

}  // namespace eical::tools::report
