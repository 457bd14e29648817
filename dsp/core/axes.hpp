#pragma once
// Machine axis names ("x", "y", "z" → 0, 1, 2) and which sensor moves an axis.
#include "dsp/core/run_meta.hpp"

#include <array>
#include <string_view>

namespace eical::dsp {

// 'x', 'y', 'z' → 0, 1, 2; anything else −1.
constexpr int axis_index(char c) noexcept { return c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : -1; }
inline int axis_index(std::string_view a) noexcept { return a.size() == 1 ? axis_index(a[0]) : -1; }

// Which sensor moves machine axis j: 0 the table's, 1 the head's, −1 neither.
inline int axis_owner(const MachineLayout& m, int j) noexcept {
  for (const auto& a : m.table_axes)
    if (axis_index(a) == j) return 0;
  for (const auto& a : m.head_axes)
    if (axis_index(a) == j) return 1;
  return -1;
}

// Which sensor moves each machine axis (axis_owner of x, y, z).
inline std::array<int, 3> axis_owners(const MachineLayout& m) noexcept {
  return {axis_owner(m, 0), axis_owner(m, 1), axis_owner(m, 2)};
}

// The two axis letters right after `prefix` in a parameter name: "rotation_xy_mrad" → 0, 1.
inline bool two_axes(std::string_view name, std::string_view prefix, int& a, int& b) noexcept {
  if (name.substr(0, prefix.size()) != prefix || name.size() < prefix.size() + 2) return false;
  a = axis_index(name[prefix.size()]), b = axis_index(name[prefix.size() + 1]);
  return a >= 0 && b >= 0;
}

}  // namespace eical::dsp
