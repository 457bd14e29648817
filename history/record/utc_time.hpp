#pragma once
// UTC wall-clock time as eical writes it everywhere: run.toml's `created`, the history's
// rows, the daemon's run ids and stop records. One formatter, so that every file agrees.
#include <ctime>
#include <string>

namespace eical::history {

inline constexpr const char* kRfc3339Utc = "%Y-%m-%dT%H:%M:%SZ";  // 2026-12-02T14:08:48Z

// `t` in UTC, as strftime's `format` writes it.
std::string utc_text(std::time_t t, const char* format = kRfc3339Utc);
// Now, the same way.
std::string utc_now(const char* format = kRfc3339Utc);

}  // namespace eical::history
