#pragma once
// From measured results to one proposal per axis, never from a figure that is not
// resolved (|value| > U, k = 2; no uncertainty = not resolved):
// * an axis with a positioning run gets its deviation table (pitch: positioning.M_um) with
//   the reversal folded into its two directions — the run's own reversal if
//   positioning.B_mean_um is resolved (x̄i↑, x̄i↓ as measured), else the circles' backlash
//   of that axis if resolved (±b/2 about the mean), else none;
// * an axis with circles only gets its lost motion from their backlash figure;
// * squareness and scale mismatch are reported, not proposed (no axis table holds them).
// A table must cover the travel every input measured on its axis (and --travel).
// Unresolved figures: left out and listed (skip, eical comp's default), refused
// (InputError naming each, nothing written), or proposed anyway (allow).
#include "tools/comp/comp_inputs.hpp"
#include "tools/comp/proposal.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace eical::tools::comp {

enum class Unresolved { refuse, skip, allow };

struct TravelRange {
  int axis = 0;
  double from_mm = 0.0, to_mm = 0.0;
  std::string who;  // for the error message
};

struct PlanOptions {
  Unresolved unresolved = Unresolved::skip;
  std::vector<TravelRange> travel;  // --travel
};

struct Plan {
  std::vector<AxisProposal> axes;                    // ascending axis, only axes with a proposal
  nlohmann::json figures = nlohmann::json::array();  // every figure looked at, with its use
  nlohmann::json not_compensated = nlohmann::json::array();
  nlohmann::json skipped = nlohmann::json::array();  // inputs that give no compensation terms
  std::vector<std::string> unresolved_used;          // proposed anyway (allow)
  std::vector<std::string> unresolved_skipped;       // left out (skip)
};

Plan build_plan(const std::vector<CompInput>& inputs, const PlanOptions& o);

}  // namespace eical::tools::comp
