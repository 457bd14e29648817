#include "tools/figure_text.hpp"

#include "dsp/core/key_unit.hpp"

#include <cmath>
#include <cstdio>

namespace eical::tools {

std::string value_with_u(double value, std::optional<double> u_k2, const std::string& unit) {
  const double scale = std::max(std::abs(value), u_k2 ? *u_k2 : 0.0);
  const int d = scale >= 1000.0 ? 0 : scale >= 100.0 ? 1 : scale >= 0.1 ? 2 : 3;
  char b[96];
  if (u_k2 && std::isfinite(*u_k2))
    std::snprintf(b, sizeof b, "%.*f ± %.*f %s", d, value, d, *u_k2, unit.c_str());
  else
    std::snprintf(b, sizeof b, "%.*f %s ± ?", d, value, unit.c_str());
  return b;
}

std::string sensor_model_text(const dsp::Analysis& a) {
  if (a.sensor_model == "datasheet") return "the data sheet's sensor model";
  return "the sensor calibration (method " + a.sensor_model + ")";
}

std::optional<double> figure_u(const dsp::Analysis& a, const std::string& key, std::size_t i) {
  const auto it = a.uncertainty_k2.find(key);
  if (it == a.uncertainty_k2.end() || i >= it->second.size() || !std::isfinite(it->second[i])) return std::nullopt;
  return it->second[i];
}

}  // namespace eical::tools
