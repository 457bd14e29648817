#include "history/record/figure_names.hpp"

#include "history/record/utc_time.hpp"

#include <array>
#include <cctype>
#include <cstdio>
#include <ctime>
#include <utility>

namespace eical::history {

std::string utc_rfc3339(const std::string& text) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, n = 0;
  char sep = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2d%c%2d:%2d%n", &y, &mo, &d, &sep, &h, &mi, &n) != 6 ||
      (sep != 'T' && sep != 't' && sep != ' '))
    return "";
  std::size_t i = static_cast<std::size_t>(n);
  if (i < text.size() && text[i] == ':') {
    int used = 0;
    if (std::sscanf(text.c_str() + i, ":%2d%n", &s, &used) != 1) return "";
    i += static_cast<std::size_t>(used);
  }
  if (i < text.size() && text[i] == '.')
    for (++i; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]));) ++i;  // fraction: dropped
  long offset_s = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
    int oh = 0, om = 0;
    if (std::sscanf(text.c_str() + i + 1, "%2d:%2d", &oh, &om) != 2) return "";
    offset_s = (text[i] == '-' ? -1 : 1) * (oh * 3600L + om * 60L);
  } else if (i < text.size() && text[i] != 'Z' && text[i] != 'z') {
    return "";
  }
  if (mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || s > 60) return "";
  std::tm tm{};
  tm.tm_year = y - 1900, tm.tm_mon = mo - 1, tm.tm_mday = d, tm.tm_hour = h, tm.tm_min = mi, tm.tm_sec = s;
  return utc_text(timegm(&tm) - offset_s);
}

}  // namespace eical::history
