#include "tools/io/psd_option.hpp"

#include "dsp/core/error.hpp"

#include <stdexcept>

namespace eical::tools {

namespace {

struct AxisPair {
  std::string axis;
  double a = 0.0, b = 0.0;
};

// AXIS:A,B with AXIS one of `axes`; `option` and `form` name the option in the message.
AxisPair parse_axis_pair(const std::string& text, const std::string& option, const std::string& form,
                         const std::string& axes = "xy") {
  const auto colon = text.find(':');
  const auto comma = text.find(',', colon == std::string::npos ? 0 : colon);
  if (colon == std::string::npos || comma == std::string::npos)
    throw dsp::InputError(option + " '" + text + "': expected " + form);
  AxisPair p;
  p.axis = text.substr(0, colon);
  if (p.axis.size() != 1 || axes.find(p.axis[0]) == std::string::npos)
    throw dsp::InputError(option + " '" + text + "': the axis is one of " + axes);
  try {
    std::size_t used_a = 0, used_b = 0;
    const std::string a = text.substr(colon + 1, comma - colon - 1), b = text.substr(comma + 1);
    p.a = std::stod(a, &used_a), p.b = std::stod(b, &used_b);
    if (used_a != a.size() || used_b != b.size()) throw std::invalid_argument("trailing text");
  } catch (const std::exception&) {
    throw dsp::InputError(option + " '" + text + "': the two values are not numbers (" + form + ")");
  }
  return p;
}

}  // namespace

dsp::PsdSpec parse_psd(const std::string& text) {
  const AxisPair p = parse_axis_pair(text, "--psd", "MEASURES:CX,CY, e.g. x:0,-10");
  dsp::PsdSpec s;
  s.measures = p.axis;
  s.center_mm[0] = p.a, s.center_mm[1] = p.b;
  return s;
}

TravelOption parse_travel(const std::string& text) {
  const AxisPair p = parse_axis_pair(text, "--travel", "AXIS:LO,HI in mm, e.g. x:0,100", "xyz");
  if (!(p.b > p.a)) throw dsp::InputError("--travel '" + text + "': HI must lie above LO");
  return {p.axis[0] - 'x', p.a, p.b};
}

}  // namespace eical::tools
