#pragma once
// The support schedule of a measurement on a coarser time grid, for the uncertainty's
// covariance and model responses: a long test (a ballbar-size circle at 1 m/min runs for
// minutes, a million samples) would otherwise need gigabytes of smoother gains. The error
// of the path is smooth (double-integrated noise), so blocks of q samples lose nothing:
//   * a block's standstill samples become one velocity observation with σ/√(count),
//     a held axis' (NBS) likewise; ringing standstills keep their window means;
//   * a block's fixes of one strip become one fix with the combined variance of what the
//     pipeline weighted each with (strip noise, the sensor model's share, the floor);
//   * the process noise over the block's span is exact (the model discretises any step).
// Coarse sample j stands for the end of its block, fine sample min((j+1)q − 1, n − 1).
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace eical::dsp::uncertainty {

struct CoarseSchedule {
  std::size_t block = 1;  // q
  std::vector<std::int64_t> sample_index;
  std::vector<std::size_t> fine_end;  // fine (sensor-time) trace position of each coarse sample
  fusion::SupportSchedule schedule;
  std::vector<double> fix_noise_um;  // per coarse fix: its strips' own noise (without the model's share)
  fusion::ErrorModel model;          // the pipeline's, with the per-sample σ folded into the schedule
};

// The schedule the pipeline used, as coarsen() reads it: also without the trace's sample
// indices in memory (a streamed analysis knows them from the recorded steps).
struct FineSchedule {
  const fusion::SupportSchedule* schedule = nullptr;  // one flag per trace sample, the fixes, the window means
  std::size_t samples = 0;                            // trace samples coarsened (at most schedule->flags.size())
  std::function<std::int64_t(std::size_t)> index_at;  // sample index of trace sample k (read about block ends only)
  // ZUPT σ per sample as bits (true: −1, unused) when schedule->zupt_sigma_um_s is empty
  // (fusion::SmootherTrack::zupt_unused); absent: 0, each standstill sample used.
  const std::vector<bool>* zupt_unused = nullptr;
  std::uint8_t flag_mask = 0xFF;  // the flags kept (a diverged fusion: move starts and invalid samples)
  double fs_hz = 0.0;             // the trace's sample rate: the way's differences give the fixes' velocity
};

CoarseSchedule coarsen(const FineSchedule& in, const fusion::ErrorModel& model, std::size_t q);

// `fine`: the schedule the pipeline used (one flag per trace sample); `block` ≥ 1.
CoarseSchedule coarsen(const fusion::SupportSchedule& fine, const std::vector<std::int64_t>& sample_index,
                       const fusion::ErrorModel& model, std::size_t block, double fs_hz);

}  // namespace eical::dsp::uncertainty
