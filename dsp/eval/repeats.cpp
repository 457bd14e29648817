#include "dsp/eval/repeats.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::eval {
namespace {

struct Segment {
  std::size_t begin = 0, end = 0;  // trace positions [begin, end)
};

// Same set-point path relative to the segment's start, within one sample of motion (the
// marks fall on whole samples while the NC's blocks do not).
bool same_path(const std::vector<Eigen::Vector3d>& cmd, const Segment& a, const Segment& b, std::size_t len) {
  double step = 0.0;
  for (std::size_t i = 1; i < len; ++i) step = std::max(step, (cmd[a.begin + i] - cmd[a.begin + i - 1]).norm());
  const double tol_mm = 1e-6 + 1.5 * step;
  const Eigen::Vector3d oa = cmd[a.begin], ob = cmd[b.begin];
  for (std::size_t i = 0; i < len; i += 7)
    if (((cmd[a.begin + i] - oa) - (cmd[b.begin + i] - ob)).norm() > tol_mm) return false;
  return true;
}

}  // namespace

std::vector<RepeatGroup> average_repeats(const RepeatInput& in) {
  std::vector<RepeatGroup> out;
  if (!in.sample_index || !in.pos_mm || !in.cmd_mm) return out;
  const auto& idx = *in.sample_index;
  const auto& pos = *in.pos_mm;
  const auto& cmd = *in.cmd_mm;
  const std::size_t n = std::min({idx.size(), pos.size(), cmd.size()});
  std::vector<std::int64_t> marks = in.marks;
  std::sort(marks.begin(), marks.end());
  std::vector<Segment> segs;
  for (std::size_t i = 0; i + 1 < marks.size(); ++i) {
    const auto b = std::lower_bound(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(n), marks[i]);
    const auto e = std::lower_bound(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(n), marks[i + 1]);
    if (b == idx.begin() + static_cast<std::ptrdiff_t>(n) || e == idx.begin() + static_cast<std::ptrdiff_t>(n)) continue;
    Segment s{static_cast<std::size_t>(b - idx.begin()), static_cast<std::size_t>(e - idx.begin())};
    if (s.end <= s.begin + 1 || idx[s.end - 1] - idx[s.begin] != static_cast<std::int64_t>(s.end - 1 - s.begin)) continue;  // gap
    segs.push_back(s);
  }
  std::vector<bool> used(segs.size(), false);
  for (std::size_t i = 0; i < segs.size(); ++i) {
    if (used[i]) continue;
    std::vector<std::size_t> members{i};
    std::size_t len = segs[i].end - segs[i].begin;
    for (std::size_t j = i + 1; j < segs.size(); ++j) {
      if (used[j]) continue;
      const std::size_t lj = segs[j].end - segs[j].begin;
      if (lj + 2 < len || len + 2 < lj) continue;  // the marks' rounding: ±1 sample each
      const std::size_t common = std::min(len, lj);
      if (!same_path(cmd, segs[i], segs[j], common)) continue;
      members.push_back(j);
      len = common;
    }
    if (members.size() < 2) continue;
    RepeatGroup g;
    g.samples = len;
    g.mean_deviation_um.assign(len, Eigen::Vector3d::Zero());
    g.spread_um.assign(len, Eigen::Vector3d::Zero());
    const double nr = static_cast<double>(members.size());
    for (std::size_t m : members) {
      used[m] = true;
      g.first_index.push_back(idx[segs[m].begin]);
      for (std::size_t k = 0; k < len; ++k) g.mean_deviation_um[k] += (pos[segs[m].begin + k] - cmd[segs[m].begin + k]) * 1000.0 / nr;
    }
    const Segment& first = segs[members.front()];
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 1; k < len && !g.axis_moves[a]; ++k) g.axis_moves[a] = std::abs(cmd[first.begin + k][a] - cmd[first.begin][a]) > 1e-6;
    Eigen::Vector3d mask;
    for (int a = 0; a < 3; ++a) mask[a] = g.axis_moves[a] ? 1.0 : 0.0;
    double ss_spread = 0.0, ss_mean = 0.0;
    for (std::size_t k = 0; k < len; ++k) {
      Eigen::Vector3d var = Eigen::Vector3d::Zero();
      for (std::size_t m : members) var += ((pos[segs[m].begin + k] - cmd[segs[m].begin + k]) * 1000.0 - g.mean_deviation_um[k]).cwiseAbs2();
      g.spread_um[k] = (var / (nr - 1.0)).cwiseSqrt();
      ss_spread += g.spread_um[k].cwiseProduct(mask).squaredNorm();
      ss_mean += g.mean_deviation_um[k].cwiseProduct(mask).squaredNorm();
    }
    g.scatter_rms_um = std::sqrt(ss_spread / static_cast<double>(len));
    g.mean_rms_um = std::sqrt(ss_mean / static_cast<double>(len));
    out.push_back(std::move(g));
  }
  std::sort(out.begin(), out.end(), [](const RepeatGroup& a, const RepeatGroup& b) { return a.repeats() > b.repeats(); });
  return out;
}

}  // namespace eical::dsp::eval
