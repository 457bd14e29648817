#include "tools/io/psd_option.hpp"

#include <stdexcept>

namespace eical::tools {

dsp::PsdSpec parse_psd(const std::string& text) {
  const auto colon = text.find(':');
  const auto comma = text.find(',', colon == std::string::npos ? 0 : colon);
  if (colon == std::string::npos || comma == std::string::npos)
    throw std::runtime_error("--psd '" + text + "': expected MEASURES:CX,CY (e.g. x:0,-10)");
  dsp::PsdSpec s;
  s.measures = text.substr(0, colon);
  if (s.measures != "x" && s.measures != "y") throw std::runtime_error("--psd '" + text + "': a strip measures x or y");
  try {
    s.center_mm[0] = std::stod(text.substr(colon + 1, comma - colon - 1));
    s.center_mm[1] = std::stod(text.substr(comma + 1));
  } catch (const std::exception&) {
    throw std::runtime_error("--psd '" + text + "': the centre is not two numbers");
  }
  return s;
}

}  // namespace eical::tools
