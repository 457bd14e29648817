#pragma once
// Reading a figure and its uncertainty out of an eical-result/1 document by its result
// key (`uncertainty_k2` keys, docs/result-format.md), and the one rule of when it says
// something: resolved ⇔ |value| > U (k = 2) (dsp/uncertainty/resolved.hpp). For `eical
// comp`, the reports and scripts: a figure that is not resolved is shown as such and is
// never turned into compensation.
//
// Keys name a path through the document: "circle.circular_deviation_G_um",
// "positioning.vdi3441.P_um", and through arrays of objects, one value per element:
// "positioning.per_target.mean_um", "rectangle.sides.straightness_um". Arrays of pairs
// ("rectangle.corner_errors_um": [[x, y], …]) are indexed row by row (2i: x, 2i + 1: y).
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace eical::drivers {

// The figure's values in document order (null → NaN); empty when the key is absent.
std::vector<double> figure_values(const nlohmann::json& result, const std::string& key);
// Its expanded uncertainties, element by element (same order); empty when absent.
std::vector<double> figure_uncertainty(const nlohmann::json& result, const std::string& key);
// Element `index` of both (nullopt when either is missing or not finite).
std::optional<double> figure_value(const nlohmann::json& result, const std::string& key, std::size_t index = 0);
std::optional<double> uncertainty_k2(const nlohmann::json& result, const std::string& key, std::size_t index = 0);
// |value| > U; false when the figure or its uncertainty is missing.
bool figure_resolved(const nlohmann::json& result, const std::string& key, std::size_t index = 0);

}  // namespace eical::drivers
