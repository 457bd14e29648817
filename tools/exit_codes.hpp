#pragma once
#include "dsp/analysis/conformance_kind.hpp"
#include "dsp/analysis/verdict_kind.hpp"

#include <optional>
// Exit status of `eical` (docs/command-line.md): scripts and an NC's PLC can tell a good
// test from one to repeat without reading its output.
namespace eical::tools {

inline constexpr int kExitOk = 0;             // done; analyze: verdict ok
inline constexpr int kExitError = 1;          // bad input, usage error, or a failure (one line on stderr)
inline constexpr int kExitDegraded = 2;       // analyze: verdict degraded (the flags say why)
inline constexpr int kExitNotMeasurable = 3;  // analyze: verdict not_measurable (the reasons say why)
// analyze --tolerances, verdict ok: ISO 14253-1's decision for the run.
inline constexpr int kExitNonConforming = 4;  // non-conformance proven
inline constexpr int kExitUndecided = 5;      // the uncertainty zone straddles a tolerance
inline constexpr int kExitIncomplete = 6;     // plan: its --deadline passed; the output says what was not evaluated

// The exit status of a result's verdict.
int verdict_exit_code(dsp::Verdict verdict);
// The same, and with a conformance decision (analyze --tolerances) its status when the
// verdict is ok: a degraded or unmeasurable run's decision is not the headline.
int result_exit_code(dsp::Verdict verdict, const std::optional<dsp::Conformance>& conformance);

}  // namespace eical::tools
