#pragma once
// The arrays behind a result's plot, as the Trace topic carries them: the circle's radius
// deviation over angle (per revolution and direction), or for axis programs the measured
// minus commanded position along the program axis over time. Decimated by a whole stride
// so that a long measurement stays a reasonable DDS sample.
#include "drivers/dds/messages.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"

#include <cstddef>
#include <optional>

namespace eical::daemon {

// nullopt when the analysis has nothing to plot (no circle and no measured trace).
std::optional<drivers::dds::TraceMsg> make_trace(const dsp::Run& run, const dsp::Analysis& analysis,
                                                 std::size_t max_points);

}  // namespace eical::daemon
