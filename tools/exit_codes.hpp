#pragma once
#include <string>
// Exit status of `eical` (README "Exit status"): scripts and an NC's PLC can tell a good
// test from one to repeat without reading its output.
namespace eical::tools {

inline constexpr int kExitOk = 0;             // done; analyze: verdict ok
inline constexpr int kExitError = 1;          // bad input, usage error, or a failure (one line on stderr)
inline constexpr int kExitDegraded = 2;       // analyze: verdict degraded (the flags say why)
inline constexpr int kExitNotMeasurable = 3;  // analyze: verdict not_measurable (the reasons say why)
inline constexpr int kExitIncomplete = 4;     // plan: its --deadline passed; the output says what was not evaluated

// The exit status of a result's verdict ("ok", "degraded", "not_measurable").
int verdict_exit_code(const std::string& verdict);

}  // namespace eical::tools
