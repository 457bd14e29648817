#pragma once
// A PSD strip on the command line: MEASURES:CX,CY (e.g. x:0,-10: the strip measures x, its
// centre at x = 0, y = −10, as run.toml's [[psd]]). gen-nc identify and plan take it.
#include "dsp/core/run_meta.hpp"

#include <string>

namespace eical::tools {

// Throws naming the option text when it is not MEASURES:CX,CY with MEASURES x or y.
dsp::PsdSpec parse_psd(const std::string& text);

}  // namespace eical::tools
