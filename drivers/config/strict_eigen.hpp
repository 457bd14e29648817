#pragma once
// Eigen vectors and matrices from a StrictTable (scenarios, run.toml's sections).
#include "drivers/config/strict_toml.hpp"

#include <Eigen/Core>

#include <string_view>

namespace eical::drivers {

// Three numbers, or `fallback` when the key is absent (finish() only rejects present keys).
inline Eigen::Vector3d vec3_or(StrictTable& t, std::string_view key, const Eigen::Vector3d& fallback) {
  if (!t.has(key)) return fallback;
  const auto v = t.numbers(key, 3);
  return {v[0], v[1], v[2]};
}

}  // namespace eical::drivers
