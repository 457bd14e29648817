#include "dsp/comp/standstills.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::comp {

std::vector<Standstill> standstills(const Measurement& m) {
  std::vector<Standstill> out;
  const std::size_t n = m.cmd_mm.size();
  auto at_rest = [&](std::size_t i, std::size_t j) {
    return (m.cmd_mm[i] - m.cmd_mm[j]).cwiseAbs().maxCoeff() < 1e-6;
  };  // 1 nm
  for (const auto& t : m.triggers) {
    if (t.code != trigger::segment_mark) continue;
    const auto it = std::lower_bound(m.sample_index.begin(), m.sample_index.end(), t.sample_index);
    if (it == m.sample_index.end() || it == m.sample_index.begin()) continue;
    const auto k = static_cast<std::size_t>(it - m.sample_index.begin());
    std::size_t end = k;
    while (end + 1 < n && at_rest(end + 1, k)) ++end;
    const std::size_t from = k + (end - k) / 2;
    if (end <= from) continue;  // a mark inside a move
    Standstill s;
    s.cmd_mm = m.cmd_mm[k];
    for (std::size_t i = from; i <= end; ++i) {
      s.dev_um += (m.pos_mm[i] - m.cmd_mm[i]) * 1000.0;
      if (i < m.sigma_um.size() && m.sigma_um[i].allFinite()) s.sigma_um += m.sigma_um[i];
    }
    s.dev_um /= static_cast<double>(end - from + 1);
    s.sigma_um /= static_cast<double>(end - from + 1);
    // The direction each axis came from: the last sample where it differed.
    for (int a = 0; a < 3; ++a) {
      std::size_t b = k;
      while (b > 0 && std::abs(m.cmd_mm[b][a] - m.cmd_mm[k][a]) < 1e-6) --b;
      const double d = m.cmd_mm[k][a] - m.cmd_mm[b][a];
      s.approach[a] = std::abs(d) < 1e-6 ? 0 : (d > 0 ? 1 : -1);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace eical::dsp::comp
