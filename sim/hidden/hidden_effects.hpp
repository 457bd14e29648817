#pragma once
// Runs with effects hidden among realistic tolerances: what `eical explain` must see
// through (issue 7), and what `eical simulate --hide` writes.
//
// Every run carries the background the sample runs carry (tests/data/*/truth.toml): sensors
// within their data sheet (k1 ±400 ppm, k2/k3 ±5 %, f0 ±1 %, ζ ±0.01, cross terms and
// mounting ±0.2 mrad, bias walk, a slowly warming case), Earth rate, position loops with
// 99 % feed-forward, a well-kept machine (backlash, spikes, cyclic and straightness below
// 0.3 µm, squareness ±2.5 µrad, scale ±3 ppm), PSD strips with their nonlinearity and a
// KGM with its scale and interpolation errors. On top: the named effects at the sizes a
// machine or sensor shows when something is off (hidden_effects.cpp lists the ranges).
#include "sim/scenario.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace eical::sim {

// Programs the sample runs use, with the sizes drawn per seed:
//   "circle": ISO 230-4 circle R 8..15 mm, 2000..3000 mm/min, 5 revolutions, PSD
//             configuration B, KGM on x and y;
//   "step":   x 0 → 40..60 mm and back, 3 runs at 3250..6500 mm/min, 0.5 s dwell, KGM.
// Both with the table moving x and y, or (every other seed) the table x and the head y.
// One seed is one machine: the same sensors, errors and hidden sizes under either program
// (as far as an effect's draw does not depend on which axes the program moves).
const std::vector<std::string>& hidden_programs();

// The program an effect shows itself in best (circle for the geometry and the loops, step
// for what needs acceleration or standstills: the resonance rings after every ramp).
dsp::ProgramKind program_for(const std::string& effect);
// Several effects: a circle when any of them needs two moving axes (geometry, loops),
// else the step.
dsp::ProgramKind program_for(const std::vector<std::string>& effects);

// Every effect name of run-format.md's table that can be hidden.
const std::vector<std::string>& hideable_effects();

// A run of `program` with `effects` injected (empty: a baseline) over the background.
// Throws InputError for an unknown effect or program.
Scenario hidden_effect_scenario(const std::vector<std::string>& effects, dsp::ProgramKind kind, std::uint64_t seed);

}  // namespace eical::sim
