#pragma once
// Axis-tagged pairs on the command line, AXIS:A,B:
//   --psd MEASURES:CX,CY   a PSD strip (e.g. x:0,-10: it measures x, its centre at x = 0,
//                          y = −10, as run.toml's [[psd]]); gen-nc identify and plan take it;
//   --travel AXIS:LO,HI    a travel: where gen-nc identify's swings must stay, what
//                          eical comp's table must cover.
#include "dsp/core/run_meta.hpp"

#include <string>
#include <vector>

namespace eical::tools {

// Throws naming the option text when it is not MEASURES:CX,CY with MEASURES x or y.
dsp::PsdSpec parse_psd(const std::string& text);

struct TravelOption {
  int axis = 0;  // 0 = x, 1 = y, 2 = z
  double lo_mm = 0.0, hi_mm = 0.0;
};
// Throws naming the option text when it is not AXIS:LO,HI with AXIS x, y or z and LO < HI.
TravelOption parse_travel(const std::string& text);

}  // namespace eical::tools
