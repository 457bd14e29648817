#pragma once
// The volumetric model file (eical-volumetric/1 TOML): the 21-parameter model of a 3-axis
// machine, hand-written (config/examples/volumetric-example.toml) or fitted by
// `eical volumetric --fit`, with u_k2 per support point and observed = false for what the
// runs cannot observe. Read strictly: every error names the file, line and key.
#include "dsp/comp/volumetric_fit.hpp"

#include <string>
#include <vector>

namespace eical::tools {

dsp::comp::VolumetricFit read_volumetric_model(const std::string& file);

// The file's text; `runs` (one line each) go into its opening comment.
std::string volumetric_model_toml(const dsp::comp::VolumetricFit& fit, const std::vector<std::string>& runs);

}  // namespace eical::tools
