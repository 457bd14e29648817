#pragma once
// Logging for a systemd service: one line per message on stderr with the sd-daemon
// priority prefix ("<3>" = error ...), which journald turns into the PRIORITY field.
// Not for the per-sample path (it formats and writes).
#include <cstdarg>

namespace eical::daemon {

enum class LogLevel { error = 3, warning = 4, notice = 5, info = 6, debug = 7 };

void log(LogLevel level, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

}  // namespace eical::daemon
