#include "drivers/results/resolved.hpp"

#include "dsp/uncertainty/resolved.hpp"

#include <cmath>
#include <limits>

namespace eical::drivers {
namespace {

void flatten(const nlohmann::json& j, std::vector<double>& out) {
  if (j.is_number())
    out.push_back(j.get<double>());
  else if (j.is_null())
    out.push_back(std::numeric_limits<double>::quiet_NaN());
  else if (j.is_array())
    for (const auto& e : j) flatten(e, out);
}

// Follows the dotted path; through an array of objects each element continues the path.
void walk(const nlohmann::json& node, const std::vector<std::string>& parts, std::size_t i, std::vector<double>& out,
          bool& found) {
  if (i == parts.size()) {
    found = true;
    flatten(node, out);
    return;
  }
  if (node.is_object()) {
    const auto it = node.find(parts[i]);
    if (it != node.end()) walk(*it, parts, i + 1, out, found);
  } else if (node.is_array()) {
    for (const auto& e : node)
      if (e.is_object()) walk(e, parts, i, out, found);
  }
}

std::vector<std::string> split(const std::string& key) {
  std::vector<std::string> p;
  std::size_t a = 0;
  for (std::size_t b = key.find('.'); b != std::string::npos; a = b + 1, b = key.find('.', a))
    p.push_back(key.substr(a, b - a));
  p.push_back(key.substr(a));
  return p;
}

std::optional<double> element(const std::vector<double>& v, std::size_t index) {
  if (index >= v.size() || !std::isfinite(v[index])) return std::nullopt;
  return v[index];
}

}  // namespace

std::vector<double> figure_values(const nlohmann::json& result, const std::string& key) {
  std::vector<double> out;
  bool found = false;
  walk(result, split(key), 0, out, found);
  return out;
}

std::vector<double> figure_uncertainty(const nlohmann::json& result, const std::string& key) {
  std::vector<double> out;
  const auto u = result.find("uncertainty_k2");
  if (u == result.end() || !u->is_object()) return out;
  const auto it = u->find(key);
  if (it != u->end()) flatten(*it, out);
  return out;
}

std::optional<double> figure_value(const nlohmann::json& result, const std::string& key, std::size_t index) {
  return element(figure_values(result, key), index);
}

std::optional<double> uncertainty_k2(const nlohmann::json& result, const std::string& key, std::size_t index) {
  return element(figure_uncertainty(result, key), index);
}

bool figure_resolved(const nlohmann::json& result, const std::string& key, std::size_t index) {
  const auto v = figure_value(result, key, index);
  const auto u = uncertainty_k2(result, key, index);
  return v && u && dsp::uncertainty::resolved(*v, *u);
}

}  // namespace eical::drivers
