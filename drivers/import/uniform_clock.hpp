#pragma once
// A recording with jittered time stamps onto a uniform clock (what eical-run/1 needs):
//  1. dt = median of the stamp differences; a difference above 1.5·dt is a gap (unless
//     the sample was only late: the next difference is short by as much), whose missing
//     samples are lost frames (round(gap/dt) − 1 of them);
//  2. every sample gets a grid index (consecutive, or across a gap its rounded
//     length); the clock is the least-squares line through (index, stamp): its slope
//     gives fs — the median alone is limited by the stamps' printed resolution (Klipper's
//     1 µs is 0.3 % of a 3.2 kHz sample: seconds of drift over a two-minute capture);
//     the gaps are re-indexed with that fs and the line fitted again;
//  3. the jitter is the rms of the stamps about that line.
// Values on the grid: cubic Lagrange interpolation through the four stamps around the
// grid time within one unbroken stretch (fewer at a stretch's ends: quadratic or linear;
// a stretch of one sample gives its value). A grid point inside a gap is not produced: a
// lost frame, flagged gap_before on the next frame when the run is read back.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace eical::drivers {

struct UniformClock {
  double fs_hz = 0.0;
  double t0_s = 0.0;  // stamp-clock time of grid index 0 (the first sample)
  double median_dt_s = 0.0;
  double jitter_rms_s = 0.0;  // stamps about the fitted clock
  std::size_t gaps = 0;
  std::size_t lost_frames = 0;
  std::vector<std::int64_t> index;  // grid index of every input sample (0 for the first)
  [[nodiscard]] double time_at(std::int64_t i) const { return t0_s + static_cast<double>(i) / fs_hz; }
};

// Throws InputError naming `source` for fewer than 4 samples, stamps that do not increase,
// or gaps that lose more samples than were recorded.
UniformClock fit_uniform_clock(const std::vector<double>& t_s, const std::string& source);

// Values at every grid index that is not lost: grid_index[k] and values[k].
struct UniformSeries {
  std::vector<std::int64_t> grid_index;
  std::vector<Eigen::Vector3d> values;
};
UniformSeries resample(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values,
                       const UniformClock& clock);

// Values at every grid index from the first to the last sample, lost samples included,
// each by interpolate_at (an NC trace: a set-point is smooth, its gaps are bridged).
std::vector<Eigen::Vector3d> bridge_gaps(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values,
                                         const UniformClock& clock);

// A stamped series evaluated at arbitrary times (for an NC trace: cubic Lagrange through
// the four nearest stamps; held at the ends).
Eigen::Vector3d interpolate_at(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values, double at);

}  // namespace eical::drivers
