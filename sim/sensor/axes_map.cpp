#include "sim/sensor/axes_map.hpp"

#include "dsp/core/error.hpp"

#include <cmath>

namespace eical::sim {

Eigen::Matrix3d axes_map_matrix(std::string_view map, const std::string& what) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  bool used[3] = {false, false, false};
  int row = 0;
  std::size_t pos = 0;
  auto fail = [&](const std::string& why) -> Eigen::Matrix3d {
    throw dsp::InputError((what.empty() ? std::string() : what + ": ") + "axes map '" + std::string(map) + "': " + why +
                          " (expected e.g. \"x,y,z\" or \"-y,x,z\")");
  };
  while (pos <= map.size()) {
    const std::size_t comma = map.find(',', pos);
    std::string_view item = map.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    double sign = 1.0;
    if (!item.empty() && (item.front() == '-' || item.front() == '+'))
      sign = item.front() == '-' ? -1.0 : 1.0, item.remove_prefix(1);
    if (item.size() != 1 || item[0] < 'x' || item[0] > 'z') return fail("'" + std::string(item) + "' is not x, y or z");
    const int col = item[0] - 'x';
    if (used[col]) return fail(std::string(1, item[0]) + " appears twice");
    if (row > 2) return fail("more than three axes");
    used[col] = true;
    m(row++, col) = sign;
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  if (row != 3) return fail("three axes needed");
  return m;
}

std::string axes_map_text(const Eigen::Matrix3d& m) {
  std::string out;
  for (int r = 0; r < 3; ++r) {
    int col = -1;
    for (int c = 0; c < 3; ++c) {
      if (std::abs(std::abs(m(r, c)) - 1.0) < 1e-9) {
        if (col >= 0) return "";
        col = c;
      } else if (std::abs(m(r, c)) > 1e-9) {
        return "";
      }
    }
    if (col < 0) return "";
    out += (r ? "," : "") + std::string(m(r, col) < 0 ? "-" : "") + static_cast<char>('x' + col);
  }
  return out;
}

}  // namespace eical::sim
