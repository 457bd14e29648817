#include "daemon/system/log.hpp"

#include <cstdio>

namespace eical::daemon {

void log(LogLevel level, const char* fmt, ...) {
  char line[1024];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  // One fprintf per line so lines from several threads do not interleave.
  std::fprintf(stderr, "<%d>%s\n", static_cast<int>(level), line);
}

}  // namespace eical::daemon
