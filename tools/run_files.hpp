#pragma once
// What the commands write next to a run: result.json and the report folder.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"

#include <filesystem>
#include <string>

namespace eical::tools {

// Writes text to a file atomically (temporary + rename); throws naming the path.
void write_file_atomic(const std::filesystem::path& file, const std::string& text);

// One-paragraph human summary of an analysis (what `eical analyze` prints without --json).
std::string summary_text(const dsp::Run& run, const dsp::Analysis& analysis);

// The uncertainty budget of the program's headline figures (empty without one).
std::string budget_text(const dsp::Run& run, const dsp::Analysis& analysis);

}  // namespace eical::tools
