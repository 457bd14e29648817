#include "dsp/fusion/rts_smoother.hpp"

#include "dsp/core/error.hpp"
#include "dsp/fusion/checkpointed_smoother.hpp"

namespace eical::dsp::fusion {

SmootherTrack smoother_track(const std::vector<std::int64_t>& sample_index,
                             const std::vector<Eigen::Vector3d>& vel_mm_s, const std::vector<Eigen::Vector3d>& pos_mm,
                             const SupportSchedule& schedule) {
  const std::size_t n = sample_index.size();
  if (vel_mm_s.size() != n || pos_mm.size() != n || schedule.flags.size() != n)
    throw InputError("smoother: trace, velocity and schedule differ in length");
  SmootherTrack t;
  t.n = n;
  t.schedule = &schedule;
  for (std::size_t k = 1; k < n; ++k)
    if (sample_index[k] - sample_index[k - 1] != 1) t.gaps.emplace_back(k, sample_index[k] - sample_index[k - 1]);
  for (std::size_t k = 0; k < n; ++k)
    if (reads_velocity(schedule.flags[k])) t.support_vel_mm_s.push_back(vel_mm_s[k]);
  for (const auto& f : schedule.fixes) t.fix_pos_mm.push_back(f.k < n ? pos_mm[f.k][f.axis] : 0.0);
  return t;
}

// The checkpointed smoother's segments gathered into whole-measurement arrays (the same
// numbers; memory for all of them).
SmootherOutput smooth(const SmootherInput& in) {
  if (!in.sample_index || !in.vel_mm_s || !in.pos_mm || !in.schedule)
    throw InputError("smoother: input arrays missing");
  const SmootherTrack track = smoother_track(*in.sample_index, *in.vel_mm_s, *in.pos_mm, *in.schedule);
  SmootherOutput out;
  const std::size_t n = track.n;
  if (n == 0) return out;
  SmootherSettings settings;
  settings.fs_hz = in.fs_hz, settings.model = in.model, settings.start_bias_sigma_um_s2 = in.start_bias_sigma_um_s2;
  settings.forward_only = in.forward_only;
  const CheckpointedSmoother smoother(track, settings);
  out.tally = smoother.tally();
  out.resets = smoother.resets();
  out.dx_um.resize(n), out.dv_um_s.resize(n), out.bias_um_s2.resize(n), out.sigma_x_um.resize(n);
  if (in.keep_gains)
    for (int a = 0; a < 3; ++a) out.gain[a].resize(n), out.p_smoothed[a].resize(n);
  SmoothedSegment seg;
  for (std::size_t j = 0; j < smoother.segments(); ++j) {
    smoother.segment(j, seg, in.keep_gains);
    std::copy(seg.dx_um.begin(), seg.dx_um.end(), out.dx_um.begin() + static_cast<std::ptrdiff_t>(seg.first));
    std::copy(seg.dv_um_s.begin(), seg.dv_um_s.end(), out.dv_um_s.begin() + static_cast<std::ptrdiff_t>(seg.first));
    std::copy(seg.bias_um_s2.begin(), seg.bias_um_s2.end(),
              out.bias_um_s2.begin() + static_cast<std::ptrdiff_t>(seg.first));
    std::copy(seg.sigma_x_um.begin(), seg.sigma_x_um.end(),
              out.sigma_x_um.begin() + static_cast<std::ptrdiff_t>(seg.first));
    if (in.keep_gains)
      for (int a = 0; a < 3; ++a) {
        std::copy(seg.gain[a].begin(), seg.gain[a].end(), out.gain[a].begin() + static_cast<std::ptrdiff_t>(seg.first));
        std::copy(seg.p_smoothed[a].begin(), seg.p_smoothed[a].end(),
                  out.p_smoothed[a].begin() + static_cast<std::ptrdiff_t>(seg.first));
      }
  }
  return out;
}

}  // namespace eical::dsp::fusion
