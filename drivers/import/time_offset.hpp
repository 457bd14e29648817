#pragma once
// The time offset between a commanded acceleration (from a set-point on its own clock)
// and a measured one (on the recorder's uniform clock), by cross-correlation:
//  * the reference r(t) — the commanded acceleration of the axes that move — is made on a
//    grid `oversample` times finer than the measurement and passed through the sensor's
//    own low-pass (its PT2, f0 and ζ from the data sheet), so that it can be shifted by
//    fractions of a sample and looks like what the sensor delivers;
//  * the measured axes (sensor frame, any mounting: each sensor axis is regressed on the
//    reference columns) are correlated with it; the score at a lag is the energy the
//    reference explains, Σ_i c_iᵀ G⁻¹ c_i (c_i: correlations of sensor axis i with the
//    reference columns, G: the reference's Gram matrix) — insensitive to the mounting's
//    signs and permutations;
//  * coarse: the whole lag range by FFT at the measurement's rate; fine: the score on the
//    fine grid ±2 samples around the coarse peak, a parabola through the best three;
//  * detection: the coarse peak against the median score over all lags (noise alone:
//    the best of N lags is ~2 ln N times the median of a χ²₃ score, ~10 for 10⁵ lags);
//  * uncertainty: block jackknife (16 contiguous blocks of the measurement, each left out
//    once): u = √((K−1)/K · Σ (τ_−k − τ̄)²). What the reference does not explain (a
//    resonance, noise) shows in the spread, not in a formula that assumes white noise.
// offset = (recorder time) − (set-point time) of the same instant.
#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace eical::drivers {

struct MeasuredSeries {
  double fs_hz = 0.0;
  double t0_s = 0.0;                     // recorder time of grid index 0
  std::vector<std::int64_t> grid_index;  // increasing; missing indices are lost frames
  std::vector<Eigen::Vector3d> values;   // sensor axes (any unit)
};

struct ReferenceSignal {
  double t_begin_s = 0.0, t_end_s = 0.0;             // set-point clock: where the reference is defined
  Eigen::Vector3d moving = Eigen::Vector3d::Ones();  // 1 for the machine axes it uses
  std::function<Eigen::Vector3d(double t_s)> accel;  // commanded acceleration (any unit)
  double sensor_f0_hz = 0.0;                         // 0: no sensor low-pass applied
  double sensor_zeta = 0.707;
};

struct OffsetEstimate {
  double offset_s = 0.0;
  double u_s = 0.0;             // standard uncertainty (k = 1): block jackknife and the response's extension
  double u_extension_s = 0.0;   // of which: the response beyond the excited band (structure_phase.hpp)
  double explained = 0.0;       // fraction of the measured variance the reference explains at the peak
  double peak_to_median = 0.0;  // coarse peak score / median score over all lags
  Eigen::Matrix3d gain = Eigen::Matrix3d::Zero();  // regression: measured (sensor axes) ≈ gain · reference
  double structure_peak = 0.0;  // the response's peak over its median magnitude (structure_phase.hpp)
  int blocks = 0;
  double fine_step_s = 0.0;
};

// Below this the peak is not told from noise (kMinPeakToMedian ≈ 10× what noise gives).
inline constexpr double kMinPeakToMedian = 100.0;

OffsetEstimate estimate_offset(const MeasuredSeries& measured, const ReferenceSignal& reference, int oversample = 8);

}  // namespace eical::drivers
