#include "dsp/fusion/crossing_fixes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

namespace eical::dsp::fusion {
namespace {

struct Merged {
  PositionFix fix;
  double pos_mm = 0.0;
};

// The readings of one crossing (indices into fixes): one fix, or each as it was.
// `previous_mm`: the mean position the strip read on the last crossing on this axis (NaN: none).
void close_crossing(const std::vector<PositionFix>& fixes, const std::vector<double>& fix_pos_mm,
                    const std::vector<std::size_t>& crossing, double scale_uncertainty, bool scale_state,
                    double& previous_mm, std::vector<Merged>& out) {
  const auto n = static_cast<double>(crossing.size());
  double var_um2 = 0.0, mean_mm = 0.0, innovation_um = 0.0, vel_mm_s = 0.0;
  for (std::size_t i : crossing) {
    var_um2 += fixes[i].sigma_um * fixes[i].sigma_um;
    vel_mm_s += fixes[i].vel_mm_s;
    mean_mm += fixes[i].position_um / 1000.0;
    innovation_um += fixes[i].position_um - fix_pos_mm[i] * 1000.0;
  }
  const double sigma_um = std::sqrt(var_um2 / n);
  mean_mm /= n, innovation_um /= n;
  const double span_um = std::abs(fix_pos_mm[crossing.back()] - fix_pos_mm[crossing.front()]) * 1000.0;
  // What the readings resolve of the position change across the crossing (their slope's σ
  // times the span, readings spread evenly) against what the scale leaves open there.
  const double resolved_um = sigma_um * std::sqrt(12.0 / n);
  const double previous = previous_mm;
  previous_mm = mean_mm;
  if (crossing.size() < 3 || !(scale_uncertainty * span_um > resolved_um)) {
    for (std::size_t i : crossing) out.push_back({fixes[i], fix_pos_mm[i]});
    return;
  }
  const std::size_t mid = crossing[crossing.size() / 2];
  Merged m{fixes[mid], fix_pos_mm[mid]};
  m.fix.position_um = fix_pos_mm[mid] * 1000.0 + innovation_um;
  m.fix.sigma_um = sigma_um / std::sqrt(n);
  m.fix.vel_mm_s = vel_mm_s / n;  // the timing's share of the mean innovation
  // The scale's share of the mean innovation is the same at every pass over the same place:
  // against the last crossing it is what the scale does between the two (the first keeps its
  // distance from the start).
  if (std::isfinite(previous) && !scale_state)
    m.fix.model_sigma_um = scale_uncertainty * std::abs(mean_mm - previous) * 1000.0;
  out.push_back(m);
}

}  // namespace

void merge_crossings(std::vector<PositionFix>& fixes, std::vector<double>& fix_pos_mm, double scale_uncertainty,
                     std::size_t max_gap_samples, const std::array<double, 3>& scale_state_ppm) {
  if (fixes.size() != fix_pos_mm.size() || fixes.size() < 3 || !(scale_uncertainty > 0.0)) return;
  // The crossings, each the readings of one strip without a gap, in the order they begin.
  std::vector<std::vector<std::size_t>> crossings;
  std::map<int, std::size_t> open;  // strip → its crossing in `crossings`
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const auto it = open.find(fixes[i].strip);
    if (it != open.end()) {
      const std::size_t last = crossings[it->second].back();
      if (fixes[i].k - fixes[last].k <= max_gap_samples && fixes[i].axis == fixes[last].axis) {
        crossings[it->second].push_back(i);
        continue;
      }
    }
    open[fixes[i].strip] = crossings.size();
    crossings.push_back({i});
  }
  std::vector<Merged> out;
  out.reserve(fixes.size());
  std::array<double, 3> previous_mm;
  previous_mm.fill(std::numeric_limits<double>::quiet_NaN());
  for (const auto& c : crossings) {
    const int axis = std::clamp(fixes[c.front()].axis, 0, 2);
    close_crossing(fixes, fix_pos_mm, c, scale_uncertainty, scale_is_a_state(scale_state_ppm, axis),
                   previous_mm[static_cast<std::size_t>(axis)], out);
  }
  std::stable_sort(out.begin(), out.end(), [](const Merged& a, const Merged& b) { return a.fix.k < b.fix.k; });
  fixes.clear(), fix_pos_mm.clear();
  for (const Merged& m : out) fixes.push_back(m.fix), fix_pos_mm.push_back(m.pos_mm);
}

}  // namespace eical::dsp::fusion
