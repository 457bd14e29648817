#pragma once
// The offline smoother of rts_smoother.hpp over a measurement of any length in bounded
// memory. The forward pass keeps the filter at the start of every segment of kSegment
// samples (a checkpoint); the backward pass recomputes each segment's filtered states
// from its checkpoint, last segment first, and keeps the smoothed state at each
// segment's start. Any segment's smoothed errors are then recomputed on demand, in any
// order, from those two. Every sample sees the same operations in the same order as in
// one pass over stored states, so the results are equal to the bit; the price is two
// more forward passes of the (cheap) error filter.
//
// Memory: one segment of filter states (kSegment × 3 axes × (e, P)) and two small
// states per segment, instead of all filtered states of the measurement. The inputs are
// the compact SmootherTrack: the schedule (one flag byte and one float per sample), the
// integrated velocity only where a velocity support reads it, the integrated position
// only at the PSD fixes, the steps that are not one sample.
#include "dsp/core/parallel_for.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/fusion/axis_filter.hpp"
#include "dsp/fusion/forward_filter.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace eical::dsp::fusion {

// True when velocity_supports() reads the integrated velocity of a sample with these flags.
constexpr bool reads_velocity(std::uint8_t flags) {
  return !(flags & schedule_flag::invalid) &&
         (flags & (schedule_flag::rest | nbs_flag(0) | nbs_flag(1) | nbs_flag(2))) != 0;
}

// What the smoother reads of a measurement's trace, without the trace.
struct SmootherTrack {
  std::size_t n = 0;                          // samples
  const SupportSchedule* schedule = nullptr;  // flags and zupt σ per sample (n of each), fixes, window means
  // (k, samples) where the step into trace sample k is not one sample (lost frames), ascending k.
  std::vector<std::pair<std::size_t, std::int64_t>> gaps;
  // The integrated velocity (mm/s) of every sample whose flags read it (reads_velocity), in order.
  std::vector<Vec3> support_vel_mm_s;
  // The integrated position (mm) along the fix's axis at each of schedule->fixes, same order.
  std::vector<double> fix_pos_mm;
  // When schedule->zupt_sigma_um_s is empty: its values as bits (true: −1, a standstill
  // sample whose velocity is not used; false: 0), an eighth of a byte per sample.
  std::vector<bool> zupt_unused;
};

struct SmootherSettings {
  double fs_hz = kDefaultFs_hz;
  ErrorModel model;
  Vec3 start_bias_sigma_um_s2 = Vec3::Constant(20.0);
  bool forward_only = false;  // the live filter's causal result, no backward pass
  // The backward pass' axes side by side with the next segment's refilter (offline; the
  // axes are independent, so the result is the same). Empty: in order.
  ParallelFor parallel;
};

// One segment's smoothed errors (subtract them), samples [first, first + size).
struct SmoothedSegment {
  std::size_t first = 0;
  std::vector<Vec3> dx_um, dv_um_s, bias_um_s2, sigma_x_um;
  // Only when asked (segment(j, out, true)): per axis and sample the gain C_k and P_k|N.
  std::array<std::vector<StateCov>, 3> gain, p_smoothed;
  [[nodiscard]] std::size_t size() const noexcept { return dx_um.size(); }
};

// Receives every segment's smoothed errors as the smoother makes them (the backward pass:
// last segment first; forward only: in order), so that a caller can keep them instead of
// having them recomputed (two more passes) — the streamed analysis spills them.
class SegmentSink {
 public:
  virtual ~SegmentSink() = default;
  virtual void restart() = 0;  // a smoothing starts (again): forget what came before
  virtual void segment(std::size_t j, const SmoothedSegment& s) = 0;
};

class CheckpointedSmoother {
 public:
  static constexpr std::size_t kSegment = 4096;

  // Runs the forward pass and, unless forward_only, the backward pass. The track must
  // outlive the smoother (segment() reads it again). Throws InputError when the track's
  // arrays do not match its length. (segment_samples: tests check that the split changes
  // nothing.)
  CheckpointedSmoother(const SmootherTrack& track, const SmootherSettings& settings,
                       std::size_t segment_samples = kSegment, SegmentSink* sink = nullptr);
  [[nodiscard]] std::size_t segment_samples() const noexcept { return seg_; }

  [[nodiscard]] std::size_t segments() const noexcept { return checkpoints_.size(); }
  // Recomputes segment j (0 ≤ j < segments()).
  void segment(std::size_t j, SmoothedSegment& out, bool keep_gains = false) const;

  [[nodiscard]] const std::array<std::array<SupportTally, kSupportKinds>, 3>& tally() const noexcept { return tally_; }
  [[nodiscard]] std::size_t resets() const noexcept { return reset_count_; }
  // Axis a's scale error (ppm) and its σ as the whole measurement shows them: a constant
  // state (no process noise), so the filter's at the end is the smoothed one at every sample.
  [[nodiscard]] std::pair<double, double> scale_ppm(int a) const noexcept {
    const auto i = static_cast<std::size_t>(a);
    return {end_scale_ppm_[i], end_scale_sigma_ppm_[i]};
  }
  // Axis a's timing error (µs) and its σ, the same way.
  [[nodiscard]] std::pair<double, double> timing_us(int a) const noexcept {
    const auto i = static_cast<std::size_t>(a);
    return {end_timing_us_[i], end_timing_sigma_us_[i]};
  }
  // False when a smoothed (or, forward only, filtered) position or velocity error is not
  // finite: the model met values it cannot take.
  [[nodiscard]] bool finite() const noexcept { return finite_; }

 private:
  // Where the forward pass stood at the start of a segment.
  struct Checkpoint {
    ForwardFilter filter;
    std::size_t next_fix = 0, next_mean = 0, next_vel = 0, next_gap = 0;
  };
  struct SegmentStates {
    std::size_t first = 0;
    std::array<std::vector<State>, 3> e;
    std::array<std::vector<StateCov>, 3> p;
    std::vector<std::int64_t> gap;  // the step into each sample
  };
  [[nodiscard]] std::int64_t gap_into(std::size_t k, std::size_t& next_gap) const noexcept;
  // The forward filter's code over samples [first, last) from checkpoint c, which it
  // leaves at `last`; the filtered states when asked.
  void forward(Checkpoint& c, std::size_t first, std::size_t last, SegmentStates* states) const;
  void refilter(std::size_t j, SegmentStates& states) const;
  // The backward pass over every segment (the constructor's second half); `states` holds
  // the last segment's filtered states.
  void smooth_backward(SegmentStates& states, SegmentSink* sink);
  // The errors of segment states into `out` (σ from P), the scale's share added.
  void output(const SegmentStates& s, SmoothedSegment& out) const;
  // The backward recursion over the segment's states (filtered in, smoothed out), from the
  // smoothed state of sample `last` (the next segment's first; none for the last segment,
  // whose last sample is smoothed as filtered); the gains when asked.
  void backward(SegmentStates& s, std::size_t last, const std::array<State, 3>* e_next,
                const std::array<StateCov, 3>* p_next, std::array<std::vector<StateCov>, 3>* gains, int first_axis = 0,
                int end_axis = 3) const;

  const SmootherTrack& track_;
  SmootherSettings settings_;
  std::size_t seg_ = kSegment;
  Discrete nominal_;
  std::vector<PositionFix> fixes_;  // sorted by k (stable), with their integrated position
  std::vector<double> fix_pos_mm_;
  std::vector<VelocityMean> means_;               // sorted by k (stable)
  std::vector<Checkpoint> checkpoints_;           // one per segment
  std::vector<std::array<State, 3>> smoothed_e_;  // smoothed state at each segment's first sample
  std::vector<std::array<StateCov, 3>> smoothed_p_;
  // Per axis: (sample, added process noise) of each covariance reset, ascending sample.
  std::array<std::vector<std::pair<std::size_t, Vec3>>, 3> extra_;
  std::array<std::array<SupportTally, kSupportKinds>, 3> tally_{};
  std::size_t reset_count_ = 0;
  std::array<double, 3> end_scale_ppm_{}, end_scale_sigma_ppm_{};
  std::array<double, 3> end_timing_us_{}, end_timing_sigma_us_{};
  bool finite_ = true;
};

}  // namespace eical::dsp::fusion
