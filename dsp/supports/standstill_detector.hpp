#pragma once
#include "dsp/core/sample_rate.hpp"
// Automatic standstill detection for ZUPT (ch. 3.4.2, 8.3.1): no hand-set windows. A
// sample is at rest when, over the last W samples,
//   1 the relative acceleration carries no more energy than the sensors' noise: the
//     generalised likelihood ratio test of foot-mounted inertial navigation (Skog et al.,
//     "Zero-velocity detection — an algorithm evaluation", 2010) with the acceleration
//     variance only,  T = Σ |a|² / (3 W σ²) ≤ γ,  γ = 1 + z √(2 / 3W)
//     (T is χ²(3W)/3W at rest; z = 4 keeps false alarms below 1e-4 per window);
//   2 the NC set-point has not moved for W samples plus the DAQ delay (the sensors see
//     the motion that late) — or, in a run without set-point, the integrated velocity is
//     small against its own uncertainty (an axis gliding at constant speed has no
//     acceleration either).
// σ² is learnt in the rest window after M101 (it then includes what the machine's
// floor adds; never below a quarter of the data sheet's), the data sheet's until then.
// Common vibration cancels in head − table; relative vibration raises σ² with it.
//
// A machine still ringing after a move (its foundation mode decays over seconds; with one
// sensor, ch. 8.3.1, every vibration is "relative") fails test 1 for long. When the set-
// point has come to rest nonetheless, the sample is a standstill all the same. Either way
// the decision carries the spread of the integrated velocity over the last quarter second
// (long enough for a machine's slowest modes, a few Hz): a slow mode rings with little
// acceleration, so the velocity a zero-velocity update may trust comes from there.
#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace eical::dsp::supports {

struct StandstillOptions {
  double window_s = 0.02;
  double z = 4.0;
  double velocity_floor_mm_s = 0.02;  // plus 4 σ of the filter's velocity
  double vibration_window_s = 0.25;   // spread of the velocity of a ringing machine
};

class StandstillDetector {
 public:
  StandstillDetector() = default;
  // Allocates the window (start-up only). noise_var_mps2: per axis, per sample.
  StandstillDetector(const StandstillOptions& options, double fs_hz, double delay_samples, double noise_var_mps2);

  void set_noise(double noise_var_mps2) noexcept { var_ = std::max(noise_var_mps2, 0.25 * datasheet_var_); }
  [[nodiscard]] double noise_var() const noexcept { return var_; }
  [[nodiscard]] std::size_t window() const noexcept { return ring_.size(); }
  [[nodiscard]] std::size_t vibration_window() const noexcept { return vring_.size(); }

  struct Decision {
    bool rest = false;
    bool quiet = false;                 // test 1 passed (a confirmed, tight standstill)
    double velocity_spread_mm_s = 0.0;  // spread of the integrated velocity over the detector's window
    double vibration_sigma_mm_s = 0.0;  // ... over the vibration window (a ringing standstill's σ)
    Eigen::Vector3d window_mean_mm_s = Eigen::Vector3d::Zero();  // its mean there
    double window_lag_s = 0.0;                                   // from the window's mean time to this sample
  };
  // One sample: the bias-free relative acceleration (m/s²), the integrated velocity as
  // integrated (mm/s: its window statistics), the filter's correction of it and the σ of
  // what is left (mm/s: the glide test), whether the set-point moved at this sample
  // (cmd_valid false: no set-point).
  Decision step(const Eigen::Vector3d& accel_mps2, const Eigen::Vector3d& vel_mm_s,
                const Eigen::Vector3d& vel_correction_mm_s, double vel_sigma_mm_s, bool cmd_valid,
                bool cmd_moved) noexcept;
  void reset() noexcept;

  [[nodiscard]] double statistic() const noexcept { return t_; }

 private:
  StandstillOptions opt_;
  std::vector<double> ring_;
  std::vector<Eigen::Vector3d> vring_;  // integrated velocity, mm/s (vibration window)
  Eigen::Vector3d wsum_ = Eigen::Vector3d::Zero(), wsq_ = Eigen::Vector3d::Zero();  // over the detector's window
  std::size_t vhead_ = 0, vfilled_ = 0;
  Eigen::Vector3d vsum_ = Eigen::Vector3d::Zero(), vsq_ = Eigen::Vector3d::Zero();
  std::size_t head_ = 0, filled_ = 0, since_recompute_ = 0, bad_ = 0;
  double sum_ = 0.0, var_ = 1.0, datasheet_var_ = 1.0, fs_hz_ = kDefaultFs_hz, gamma_ = 1.0, t_ = 0.0;
  std::int64_t cmd_still_samples_ = 0, cmd_needed_ = 0;
};

}  // namespace eical::dsp::supports
