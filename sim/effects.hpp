#pragma once
// Which effects of docs/run-format.md a scenario puts into its data, read off the
// scenario's parameters (anything that differs from the nominal, ideal model).
#include "sim/scenario.hpp"

#include <string>
#include <vector>

namespace eical::sim {

// Every effect name of run-format.md's table, in its order: dsp::model::effect_catalogue's
// names (the one catalogue explain and the simulator share).
const std::vector<std::string>& effect_names();

// The effects whose parameters differ from nominal in this scenario.
std::vector<std::string> effects_in(const Scenario& scenario);

// What truth.toml calls present and background: the scenario's own lists when it has
// them (present = injected on purpose), else everything found is present.
struct EffectLists {
  std::vector<std::string> present, background;
};
EffectLists effect_lists(const Scenario& scenario);

}  // namespace eical::sim
