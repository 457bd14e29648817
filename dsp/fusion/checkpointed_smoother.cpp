#include "dsp/fusion/checkpointed_smoother.hpp"

#include "dsp/core/error.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace eical::dsp::fusion {

CheckpointedSmoother::CheckpointedSmoother(const SmootherTrack& track, const SmootherSettings& settings,
                                           std::size_t segment_samples, SegmentSink* sink)
    : track_(track),
      settings_(settings),
      seg_(std::max<std::size_t>(1, segment_samples)),
      nominal_(discretise(settings.model, 1.0 / settings.fs_hz)) {
  if (!track.schedule) throw InputError("smoother: no schedule");
  const std::size_t n = track.n;
  if (track.schedule->flags.size() != n) throw InputError("smoother: trace, velocity and schedule differ in length");
  if (track.fix_pos_mm.size() != track.schedule->fixes.size())
    throw InputError("smoother: a PSD fix without its integrated position");
  std::size_t reads = 0;
  for (const std::uint8_t f : track.schedule->flags) reads += reads_velocity(f) ? 1 : 0;
  if (track.support_vel_mm_s.size() != reads)
    throw InputError("smoother: trace, velocity and schedule differ in length");
  // Fixes and window means in sample order, whatever the caller's (stable: equal k keep theirs).
  std::vector<std::size_t> order(track.schedule->fixes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return track.schedule->fixes[a].k < track.schedule->fixes[b].k;
  });
  for (const std::size_t i : order)
    fixes_.push_back(track.schedule->fixes[i]), fix_pos_mm_.push_back(track.fix_pos_mm[i]);
  means_ = track.schedule->velocity_means;
  std::stable_sort(means_.begin(), means_.end(),
                   [](const VelocityMean& a, const VelocityMean& b) { return a.k < b.k; });
  if (sink) sink->restart();
  if (n == 0) return;
  SmoothedSegment out;

  // Forward: the live filter's code over the track, a checkpoint at each segment's start.
  Checkpoint c;
  c.filter.start(settings_.model, settings_.start_bias_sigma_um_s2);
  std::vector<CovarianceReset> resets;
  resets.reserve(4096);
  const std::size_t n_seg = (n + seg_ - 1) / seg_;
  checkpoints_.reserve(n_seg);
  SegmentStates states;
  for (std::size_t j = 0; j < n_seg; ++j) {
    const std::size_t first = j * seg_, last = std::min(n, first + seg_);
    c.filter.resets = nullptr;
    checkpoints_.push_back(c);
    c.filter.resets = &resets;
    // The last segment's filtered states are kept: the backward pass starts with them
    // (refiltering them from the checkpoint would compute the same numbers again).
    forward(c, first, last, settings_.forward_only || j + 1 == n_seg ? &states : nullptr);
    if (settings_.forward_only) {  // the filtered errors are the result: they must be finite
      for (int a = 0; a < 3; ++a)
        for (const State& e : states.e[a]) finite_ = finite_ && std::isfinite(e[0]) && std::isfinite(e[1]);
      if (sink) output(states, out), sink->segment(j, out);
    }
  }
  tally_ = c.filter.tally, reset_count_ = c.filter.reset_count;
  for (std::size_t a = 0; a < 3; ++a) {
    end_scale_ppm_[a] = c.filter.axis[a].e[kScaleState];
    end_scale_sigma_ppm_[a] = std::sqrt(std::max(c.filter.axis[a].P(kScaleState, kScaleState), 0.0));
    end_timing_us_[a] = c.filter.axis[a].e[kTimingState];
    end_timing_sigma_us_[a] = std::sqrt(std::max(c.filter.axis[a].P(kTimingState, kTimingState), 0.0));
  }
  for (const auto& r : resets) extra_[r.axis].push_back({r.k, Vec3(r.add_xx, r.add_vv, r.add_bb)});
  if (!settings_.forward_only) smooth_backward(states, sink);
}

// Backward (RTS), last segment first: each segment's filtered states again from its
// checkpoint, then the recursion down to its first sample, whose smoothed state the
// segment before it starts from. Two tasks a segment: axes x and y; axis z and the
// refilter of the segment before (the axes are independent, the refilter reads only the
// checkpoints). `states`: the last segment's, filtered.
void CheckpointedSmoother::smooth_backward(SegmentStates& states, SegmentSink* sink) {
  const std::size_t n = track_.n, n_seg = checkpoints_.size();
  SmoothedSegment out;
  smoothed_e_.resize(n_seg);
  smoothed_p_.resize(n_seg);
  const ParallelFor parallel = settings_.parallel ? settings_.parallel : sequential_for();
  SegmentStates before;
  for (std::size_t j = n_seg; j-- > 0;) {
    const std::size_t last = std::min(n, (j + 1) * seg_);
    const bool top = j + 1 == n_seg;
    const std::array<State, 3>* e_next = top ? nullptr : &smoothed_e_[j + 1];
    const std::array<StateCov, 3>* p_next = top ? nullptr : &smoothed_p_[j + 1];
    parallel(2, [&](std::size_t task) {
      if (task == 0) {
        backward(states, last, e_next, p_next, nullptr, 0, 2);
      } else {
        backward(states, last, e_next, p_next, nullptr, 2, 3);
        if (j > 0) refilter(j - 1, before);
      }
    });
    for (int a = 0; a < 3; ++a) {
      smoothed_e_[j][a] = states.e[a][0];
      smoothed_p_[j][a] = states.p[a][0];
      for (const State& e : states.e[a]) finite_ = finite_ && std::isfinite(e[0]) && std::isfinite(e[1]);
    }
    if (sink) output(states, out), sink->segment(j, out);
    std::swap(states, before);
  }
}

std::int64_t CheckpointedSmoother::gap_into(std::size_t k, std::size_t& next_gap) const noexcept {
  const auto& g = track_.gaps;
  while (next_gap < g.size() && g[next_gap].first < k) ++next_gap;
  return next_gap < g.size() && g[next_gap].first == k ? g[next_gap].second : 1;
}

void CheckpointedSmoother::forward(Checkpoint& c, std::size_t first, std::size_t last, SegmentStates* states) const {
  ForwardFilter& fwd = c.filter;
  const ErrorModel& m = settings_.model;
  const SupportSchedule& sch = *track_.schedule;
  const auto& flags = sch.flags;
  const auto& zs = sch.zupt_sigma_um_s;
  if (states) {
    states->first = first;
    for (int a = 0; a < 3; ++a) states->e[a].resize(last - first), states->p[a].resize(last - first);
    states->gap.resize(last - first);
  }
  for (std::size_t k = first; k < last; ++k) {
    fwd.k = k;
    std::int64_t gap = 1;
    if (k > 0) {
      gap = gap_into(k, c.next_gap);
      fwd.predict(gap == 1 ? nominal_ : discretise(m, static_cast<double>(gap) / settings_.fs_hz),
                  (flags[k] & schedule_flag::move_start) != 0, m);
    }
    Vec3 vel = Vec3::Zero();  // read only where the flags say so
    if (reads_velocity(flags[k])) vel = track_.support_vel_mm_s[c.next_vel++];
    const double zupt_sigma = k < zs.size() ? static_cast<double>(zs[k])
                                            : (k < track_.zupt_unused.size() && track_.zupt_unused[k] ? -1.0 : 0.0);
    fwd.velocity_supports(flags[k], vel * 1000.0, m, zupt_sigma, sch.zupt);
    for (; c.next_mean < means_.size() && means_[c.next_mean].k <= k; ++c.next_mean)
      if (means_[c.next_mean].k == k) fwd.velocity_mean(means_[c.next_mean], m, sch.zupt);
    for (; c.next_fix < fixes_.size() && fixes_[c.next_fix].k == k; ++c.next_fix) {
      const PositionFix& f = fixes_[c.next_fix];
      if (sch.cupt)
        fwd.position_fix(f.axis, fix_pos_mm_[c.next_fix] * 1000.0, f.position_um,
                         std::hypot(f.sigma_um, f.model_sigma_um), m, f.way_mm, f.vel_mm_s);
    }
    if (states) {
      states->gap[k - first] = gap;
      for (int a = 0; a < 3; ++a) states->e[a][k - first] = fwd.axis[a].e, states->p[a][k - first] = fwd.axis[a].P;
    }
  }
}

void CheckpointedSmoother::refilter(std::size_t j, SegmentStates& states) const {
  Checkpoint c = checkpoints_[j];
  c.filter.resets = nullptr;  // recorded once, by the first pass
  forward(c, j * seg_, std::min(track_.n, (j + 1) * seg_), &states);
}

void CheckpointedSmoother::backward(SegmentStates& s, std::size_t last, const std::array<State, 3>* e_next,
                                    const std::array<StateCov, 3>* p_next, std::array<std::vector<StateCov>, 3>* gains,
                                    int first_axis, int end_axis) const {
  const ErrorModel& m = settings_.model;
  const auto& flags = track_.schedule->flags;
  const std::size_t first = s.first;
  // The step into `last` (the next segment's first sample), when there is one.
  std::int64_t gap_last = 1;
  if (e_next) {
    std::size_t g = 0;
    gap_last = gap_into(last, g);
  }
  for (int a = first_axis; a < end_axis; ++a) {
    auto& e = s.e[a];
    auto& p = s.p[a];
    if (gains) (*gains)[a].assign(last - first, StateCov::Zero());
    const auto& extra = extra_[a];
    // Entries at or below `last`: the recursion at k reads those at k + 1 ≤ last.
    std::size_t next_extra = static_cast<std::size_t>(
        std::upper_bound(extra.begin(), extra.end(), last,
                         [](std::size_t v, const std::pair<std::size_t, Vec3>& x) { return v < x.first; }) -
        extra.begin());
    for (std::size_t k = e_next ? last : last - 1; k-- > first;) {
      const std::size_t i = k - first;
      const bool at_top = k + 1 == last;
      const std::int64_t gap = at_top ? gap_last : s.gap[i + 1];
      const Discrete d = gap == 1 ? nominal_ : discretise(m, static_cast<double>(gap) / settings_.fs_hz);
      StateCov pp = d.F * p[i] * d.F.transpose() + d.Q;
      if (flags[k + 1] & schedule_flag::move_start) pp(2, 2) += m.bias_step_um_s2 * m.bias_step_um_s2;
      while (next_extra > 0 && extra[next_extra - 1].first > k + 1) --next_extra;
      for (std::size_t r = next_extra; r > 0 && extra[r - 1].first == k + 1; --r)
        pp.diagonal().head<3>() += extra[r - 1].second;
      const State ep = d.F * e[i];
      const StateCov c = pp.ldlt().solve(d.F * p[i].transpose()).transpose();  // P_k Fᵀ P⁻¹ (P⁻ symmetric)
      const State& e1 = at_top ? (*e_next)[a] : e[i + 1];
      const StateCov& p1 = at_top ? (*p_next)[a] : p[i + 1];
      e[i] += c * (e1 - ep);
      p[i] += c * (p1 - pp) * c.transpose();
      p[i] = 0.5 * (p[i] + p[i].transpose());
      if (gains) (*gains)[a][i] = c;
    }
  }
}

void CheckpointedSmoother::segment(std::size_t j, SmoothedSegment& out, bool keep_gains) const {
  SegmentStates s;
  refilter(j, s);
  const std::size_t first = s.first, last = first + s.gap.size();
  if (!settings_.forward_only) {
    const bool top = j + 1 == checkpoints_.size();
    backward(s, last, top ? nullptr : &smoothed_e_[j + 1], top ? nullptr : &smoothed_p_[j + 1],
             keep_gains ? &out.gain : nullptr);
  } else if (keep_gains) {
    for (int a = 0; a < 3; ++a) out.gain[a].assign(last - first, StateCov::Zero());
  }
  if (keep_gains)
    for (int a = 0; a < 3; ++a) out.p_smoothed[a] = s.p[a];
  output(s, out);
}

void CheckpointedSmoother::output(const SegmentStates& s, SmoothedSegment& out) const {
  const std::size_t len = s.gap.size();
  out.first = s.first;
  out.dx_um.resize(len), out.dv_um_s.resize(len), out.bias_um_s2.resize(len), out.sigma_x_um.resize(len);
  const auto& way = track_.schedule->way_mm;
  for (int a = 0; a < 3; ++a) {
    const bool has_way = way.size() == track_.n;
    const bool scaled = has_way && scale_is_a_state(settings_.model, a);
    const bool timed = has_way && timing_is_a_state(settings_.model, a);
    std::size_t next_gap = 0;  // gap_into's cursor: the samples come in order
    for (std::size_t i = 0; i < len; ++i) {
      const State& e = s.e[a][i];
      const StateCov& p = s.p[a][i];
      out.dx_um[i][a] = e[0];
      out.dv_um_s[i][a] = e[1];
      out.bias_um_s2[i][a] = e[2];
      if (!scaled && !timed) {
        out.sigma_x_um[i][a] = std::sqrt(std::max(p(0, 0), 0.0));
        continue;
      }
      // The position reads h·e with h = [1, 0, 0, way, v] (support_rows.hpp: cupt_row), the
      // velocity δv + δs·v (v from the way around the sample over the samples' true spacing —
      // lost frames, a coarse grid — the same whatever the segments; δτ·a is left out).
      const std::size_t k = s.first + i, lo = k > 0 ? k - 1 : k, hi = std::min(k + 1, way.size() - 1);
      std::int64_t steps = 0;
      for (std::size_t j = lo + 1; j <= hi; ++j) steps += gap_into(j, next_gap);
      const double v_mm_s = track_.schedule->way_velocity_mm_s(lo, hi, steps, settings_.fs_hz)[a];
      const StateRow h = observe::cupt_row(scaled ? static_cast<double>(way[k][a]) : 0.0, timed ? v_mm_s : 0.0);
      out.dx_um[i][a] = h.dot(e);
      if (scaled) out.dv_um_s[i][a] += 1e-3 * v_mm_s * e[kScaleState];
      out.sigma_x_um[i][a] = std::sqrt(std::max(h.dot(p * h.transpose()), 0.0));
    }
  }
}

}  // namespace eical::dsp::fusion
