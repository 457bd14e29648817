#pragma once
// Inputs of the ISO 230-2 evaluation from outside eical: a plain deviation table (laser
// interferometer users) and the TGT_DATA / REF_DATA_FWD / REF_DATA_BWD text of the ecmc
// ISO 230-2 tools (positions in mm, deviation = REF − TGT, FWD = moving up).
#include "dsp/eval/positioning.hpp"

#include <string>

namespace eical::tools {

// CSV target_mm,run,direction,deviation_um (direction up|down, runs 1..n); every
// (target, run, direction) exactly once.
dsp::eval::PositioningInput read_deviation_csv(const std::string& file);
dsp::eval::PositioningInput read_ecmc_dat(const std::string& file);

}  // namespace eical::tools
