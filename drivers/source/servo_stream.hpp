#pragma once
// One line of the LinuxCNC servo stream as eical-halsampler writes it (halsampler -t with
// the kit's sampler cfg=ffffffu): "<sample number> Xcmd Ycmd Zcmd Xfb Yfb Zfb marker",
// or "overrun" where the HAL sampler FIFO lost samples. Parsing is allocation-free.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace eical::drivers {

struct ServoSample {
  std::int64_t number = 0;   // servo cycle count since the sampler was loaded
  double cmd_mm[3] = {};     // joint.N.pos-cmd: programmed, before LinuxCNC's compensation
  double fb_mm[3] = {};      // joint.N.motor-pos-fb
  std::uint32_t marker = 0;  // mcode-marker (diagnostic)
};

struct ServoLine {
  enum class Kind { sample, overrun } kind = Kind::sample;
  ServoSample sample;
};

// Parses one line (without its newline). nullopt and `error` set when the line is not
// the kit's format (wrong column count, not a number, not finite).
std::optional<ServoLine> parse_servo_line(std::string_view line, std::string& error);

}  // namespace eical::drivers
