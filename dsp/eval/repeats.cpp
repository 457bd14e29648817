#include "dsp/eval/repeats.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::eval {

RepeatFinder::RepeatFinder(std::vector<std::int64_t> marks) : marks_(std::move(marks)) {
  std::sort(marks_.begin(), marks_.end());
}

void RepeatFinder::open(std::size_t position, std::int64_t sample_index) {
  open_ = Segment{};
  open_.begin = position;
  open_.first_index = sample_index;
  has_open_ = true;
}

void RepeatFinder::add(std::size_t position, std::int64_t sample_index, const Eigen::Vector3d& cmd_mm) {
  // Every mark at or before this sample starts its segment here (lower_bound) and ends
  // the one before it.
  for (; next_mark_ < marks_.size() && marks_[next_mark_] <= sample_index; ++next_mark_) {
    if (has_open_) close(position);
    open(position, sample_index);
  }
  if (!has_open_) return;
  Segment& s = open_;
  const std::size_t i = s.len++;
  if (i > 0) {
    s.contiguous = s.contiguous && sample_index == prev_index_ + 1;
    s.max_step.push_back(std::max(s.max_step.back(), (cmd_mm - s.last).norm()));
    for (int a = 0; a < 3; ++a)
      if (s.first_move[a] == SIZE_MAX && std::abs(cmd_mm[a] - s.every7.front()[a]) > 1e-6) s.first_move[a] = i;
  } else {
    s.max_step.push_back(0.0);
  }
  if (i % 7 == 0) s.every7.push_back(cmd_mm);
  s.last = cmd_mm;
  prev_index_ = sample_index;
}

void RepeatFinder::finish() { has_open_ = false; }  // its end is not in the trace

// Same set-point path relative to the segment's start, within one sample of motion (the
// marks fall on whole samples while the NC's blocks do not).
bool RepeatFinder::same_path(const Segment& a, const Segment& b, std::size_t len) const {
  const double step = len >= 2 ? a.max_step[len - 1] : 0.0;
  const double tol_mm = 1e-6 + 1.5 * step;
  const Eigen::Vector3d oa = a.every7.front(), ob = b.every7.front();
  for (std::size_t i = 0; i < len; i += 7)
    if (((a.every7[i / 7] - oa) - (b.every7[i / 7] - ob)).norm() > tol_mm) return false;
  return true;
}

void RepeatFinder::close(std::size_t position) {
  has_open_ = false;
  Segment s = std::move(open_);
  (void)position;                           // s.len samples were added: the segment is [begin, position)
  if (s.len <= 1 || !s.contiguous) return;  // too short, or lost frames inside
  for (Leader& l : leaders_) {
    const std::size_t len = l.len, lj = s.len;
    if (lj + 2 < len || len + 2 < lj) continue;  // the marks' rounding: ±1 sample each
    const std::size_t common = std::min(len, lj);
    if (!same_path(l.seg, s, common)) continue;
    Segment member;
    member.begin = s.begin, member.first_index = s.first_index, member.len = s.len;
    l.members.push_back(std::move(member));
    l.len = common;
    return;
  }
  Leader l;
  l.len = s.len;
  l.seg = std::move(s);
  leaders_.push_back(std::move(l));
}

std::vector<RepeatFinder::Group> RepeatFinder::groups() const {
  std::vector<Group> out;
  for (const Leader& l : leaders_) {
    if (l.members.empty()) continue;
    Group g;
    g.len = l.len;
    g.begin.push_back(l.seg.begin), g.first_index.push_back(l.seg.first_index);
    for (const Segment& m : l.members) g.begin.push_back(m.begin), g.first_index.push_back(m.first_index);
    for (int a = 0; a < 3; ++a) g.axis_moves[a] = l.seg.first_move[a] < g.len;
    out.push_back(std::move(g));
  }
  return out;
}

RepeatAverager::RepeatAverager(std::vector<RepeatFinder::Group> groups, std::unique_ptr<Spill> spill, std::size_t keep)
    : groups_(std::move(groups)), spill_(std::move(spill)), keep_(std::max<std::size_t>(1, keep)) {
  writer_ = std::make_unique<SpillWriter<Doubles<3>>>(*spill_);
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    mean_.emplace_back(groups_[g].len, Eigen::Vector3d::Zero());
    for (std::size_t m = 0; m < groups_[g].begin.size(); ++m) order_.emplace_back(g, m);
  }
  std::sort(order_.begin(), order_.end(), [&](const auto& x, const auto& y) {
    return groups_[x.first].begin[x.second] < groups_[y.first].begin[y.second];
  });
}

void RepeatAverager::add(std::size_t position, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& cmd_mm) {
  while (next_ < order_.size()) {
    const auto [g, m] = order_[next_];
    const std::size_t begin = groups_[g].begin[m], len = groups_[g].len;
    if (position < begin) return;
    if (position >= begin + len) {
      ++next_;
      continue;
    }
    const Eigen::Vector3d d = pos_mm - cmd_mm;
    const double nr = static_cast<double>(groups_[g].begin.size());
    mean_[g][position - begin] += d * 1000.0 / nr;
    writer_->put({{d[0], d[1], d[2]}});
    return;
  }
}

std::vector<RepeatGroup> RepeatAverager::result() {
  writer_->flush();
  std::vector<RepeatGroup> out;
  // The spread group by group (one group's sums in memory at a time), each from the spill:
  // it holds the repeats' samples in time order, repeat by repeat, offset by offset.
  for (std::size_t gi = 0; gi < groups_.size(); ++gi) {
    const auto& src = groups_[gi];
    std::vector<Eigen::Vector3d> var(src.len, Eigen::Vector3d::Zero());
    std::size_t r = 0, k = 0;
    for_each_record<Doubles<3>>(*spill_, [&](const Doubles<3>& rec) {
      while (r < order_.size() && k >= groups_[order_[r].first].len) ++r, k = 0;
      if (r >= order_.size()) return;
      if (order_[r].first == gi) {
        const Eigen::Vector3d d(rec.v[0], rec.v[1], rec.v[2]);
        var[k] += (d * 1000.0 - mean_[gi][k]).cwiseAbs2();
      }
      ++k;
    });
    RepeatGroup g;
    g.samples = src.len;
    g.first_index = src.first_index;
    for (int a = 0; a < 3; ++a) g.axis_moves[a] = src.axis_moves[a];
    g.stride = std::max<std::size_t>(1, (src.len + keep_ - 1) / keep_);
    const double nr = static_cast<double>(src.begin.size());
    Eigen::Vector3d mask;
    for (int a = 0; a < 3; ++a) mask[a] = g.axis_moves[a] ? 1.0 : 0.0;
    double ss_spread = 0.0, ss_mean = 0.0;
    for (std::size_t i = 0; i < src.len; ++i) {
      const Eigen::Vector3d spread = (var[i] / (nr - 1.0)).cwiseSqrt();
      ss_spread += spread.cwiseProduct(mask).squaredNorm();
      ss_mean += mean_[gi][i].cwiseProduct(mask).squaredNorm();
      if (i % g.stride == 0) g.mean_deviation_um.push_back(mean_[gi][i]), g.spread_um.push_back(spread);
    }
    g.scatter_rms_um = std::sqrt(ss_spread / static_cast<double>(src.len));
    g.mean_rms_um = std::sqrt(ss_mean / static_cast<double>(src.len));
    std::vector<Eigen::Vector3d>().swap(mean_[gi]);
    out.push_back(std::move(g));
  }
  std::sort(out.begin(), out.end(),
            [](const RepeatGroup& a, const RepeatGroup& b) { return a.repeats() > b.repeats(); });
  return out;
}

std::vector<RepeatGroup> average_repeats(const RepeatInput& in) {
  if (!in.sample_index || !in.pos_mm || !in.cmd_mm) return {};
  const auto& idx = *in.sample_index;
  const auto& pos = *in.pos_mm;
  const auto& cmd = *in.cmd_mm;
  const std::size_t n = std::min({idx.size(), pos.size(), cmd.size()});
  RepeatFinder finder(in.marks);
  for (std::size_t k = 0; k < n; ++k) finder.add(k, idx[k], cmd[k]);
  finder.finish();
  RepeatAverager avg(finder.groups(), std::make_unique<MemorySpill>());
  for (std::size_t k = 0; k < n; ++k) avg.add(k, pos[k], cmd[k]);
  return avg.result();
}

}  // namespace eical::dsp::eval
