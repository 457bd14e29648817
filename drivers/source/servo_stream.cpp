#include "drivers/source/servo_stream.hpp"

#include <charconv>
#include <cmath>

namespace eical::drivers {
namespace {

// Next whitespace-separated field, or empty at the end of the line.
std::string_view next_field(std::string_view& s) {
  std::size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
  std::size_t j = i;
  while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
  const std::string_view f = s.substr(i, j - i);
  s.remove_prefix(j);
  return f;
}

template <class T>
bool parse_number(std::string_view f, T& out) {
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), out);
  return ec == std::errc() && end == f.data() + f.size();
}

}  // namespace

std::optional<ServoLine> parse_servo_line(std::string_view line, std::string& error) {
  std::string_view rest = line;
  const std::string_view first = next_field(rest);
  if (first == "overrun" && next_field(rest).empty()) return ServoLine{ServoLine::Kind::overrun, {}};
  ServoLine out;
  ServoSample& s = out.sample;
  if (!parse_number(first, s.number) || s.number < 0) {
    error = "expected a sample number (halsampler -t), got '" + std::string(first) + "'";
    return std::nullopt;
  }
  double* cols[6] = {&s.cmd_mm[0], &s.cmd_mm[1], &s.cmd_mm[2], &s.fb_mm[0], &s.fb_mm[1], &s.fb_mm[2]};
  for (int c = 0; c < 6; ++c) {
    const std::string_view f = next_field(rest);
    if (!parse_number(f, *cols[c]) || !std::isfinite(*cols[c])) {
      error = "column " + std::to_string(c + 2) + " (" + (c < 3 ? "cmd" : "fb") + " " + "XYZ"[c % 3] +
              ") is not a finite number: '" + std::string(f) + "' (expected sampler cfg=ffffffu)";
      return std::nullopt;
    }
  }
  const std::string_view m = next_field(rest);
  if (!parse_number(m, s.marker)) {
    error = "column 8 (mcode-marker, u32) is not an unsigned integer: '" + std::string(m) +
            "' (expected sampler cfg=ffffffu)";
    return std::nullopt;
  }
  if (!next_field(rest).empty()) {
    error = "more than 8 columns (expected sampler cfg=ffffffu)";
    return std::nullopt;
  }
  return out;
}

}  // namespace eical::drivers
