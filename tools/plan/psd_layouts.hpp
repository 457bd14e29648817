#pragma once
// The strip layouts a circle's --psd names (plan, simulate, demo, bench_u_chart): none, B
// (configuration B), B4, B8, B16 (that many strips about the circle along its path) and R4,
// R8, R16 (the same places, each strip turned radial: across the path). sim::psd_ring
// places them; docs/planning.md says which to choose.
#include "sim/scenario.hpp"

#include <string>
#include <vector>

namespace eical::tools::plan {

struct PsdLayout {
  const char* name;
  int strips;  // about a circle (none: 0, B: 2)
  sim::StripFacing facing;
};

const std::vector<std::string>& psd_layout_names();
// Throws InputError naming the choices on another name.
PsdLayout psd_layout(const std::string& name);

}  // namespace eical::tools::plan
