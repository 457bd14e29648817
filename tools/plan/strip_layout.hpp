#pragma once
// Where a planned test's PSD strips go (issue 33): each strip's centre in the program's
// coordinates (the coordinates gen-nc writes the program in: a circle about --center 0,0,
// a positioning or step test on x from its targets, a rectangle from the origin), the axis
// it measures (its length lies along that axis) and its size; as text, as JSON and as an
// SVG drawing of the test's path with the strips on it. A strip sits on the table where
// the head's light spot passes over it when the program is at that point; the spot crosses
// it moving along the axis it measures.
#include "tools/plan/predicted_uncertainty.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace eical::tools::plan {

std::string layout_text(const TestProgram& p);
nlohmann::json layout_json(const TestProgram& p);
std::string layout_svg(const TestProgram& p);

}  // namespace eical::tools::plan
