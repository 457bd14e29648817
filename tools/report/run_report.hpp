#pragma once
// The report of one analysed run: a self-contained HTML page (report.html) with the
// figures and plots a metrology engineer expects for the program kind, and every trace
// behind the plots as CSV next to it.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"

#include <filesystem>

namespace eical::tools::report {

// Writes <dir>/report.html and <dir>/trace_*.csv; returns the path of the HTML file.
std::filesystem::path write_run_report(const dsp::Run& run, const dsp::Analysis& analysis, const std::filesystem::path& dir);

}  // namespace eical::tools::report
