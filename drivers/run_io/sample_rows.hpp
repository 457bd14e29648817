#pragma once
// The text of samples.csv (run-format.md): its header line and one row per frame, exactly
// as write_run() writes them — shared with the recorder that writes a run as it is measured
// (run_appender.hpp).
#include "dsp/core/frame.hpp"
#include "dsp/core/run.hpp"

#include <string>

namespace eical::drivers {

// The header line (with its newline) for the run's channels.
std::string samples_header(const dsp::ChannelPresence& channels);

// Appends the row of `f` (with its newline) to `out`.
void append_sample_row(std::string& out, const dsp::Frame& f, const dsp::RunMeta& meta,
                       const dsp::ChannelPresence& channels);

// Shortest text that reads back to the same double; fixed notation (as people and
// spreadsheets expect: 0.0001, not 1e-04) unless the value is tiny or huge.
void append_double(std::string& out, double v);

}  // namespace eical::drivers
