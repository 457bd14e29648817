#include "history/record/utc_time.hpp"

namespace eical::history {

std::string utc_text(std::time_t t, const char* format) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[64];
  const std::size_t n = std::strftime(b, sizeof b, format, &tm);
  return {b, n};
}

std::string utc_now(const char* format) { return utc_text(std::time(nullptr), format); }

}  // namespace eical::history
