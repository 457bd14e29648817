#pragma once
// How far the measured relative acceleration lags the NC set-point's: the time alignment
// of a set-point that comes from another clock (another NC's servo stream, or a program
// reconstructed by eical's interpolator). Both accelerations are smoothed and decimated to
// ~1 kHz, then cross-correlated over the samples where the set-point moves; the peak is
// refined by a parabola through its neighbours. The lag found contains everything between
// the command and the measured motion: clock offset, and the machine's servo lag.
// Offline (evaluation thread); allocates.
#include "dsp/core/run.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace eical::dsp::align {

// Relative acceleration head − table in machine axes, m/s², one per frame of `run`: each
// sensor statically compensated (data sheet), the DAQ's group delay and the sensors'
// low-frequency PT2 delay (2ζ/ω0) removed, so sample i belongs to the set-point's time i.
// Gravity and bias are not removed (estimate_lag removes the mean of what it uses).
std::vector<Eigen::Vector3d> measured_accel_mps2(const Run& run);

// Acceleration of set-point positions (mm, one per sample at fs_hz) by the central second
// difference, m/s².
std::vector<Eigen::Vector3d> setpoint_accel_mps2(const std::vector<Eigen::Vector3d>& pos_mm, double fs_hz);

struct LagEstimate {
  bool valid = false;           // enough motion and a clear peak
  double lag_s = 0.0;           // measured = commanded delayed by lag_s
  double correlation = 0.0;     // normalised correlation at the peak (1 = same shape)
  double residual_ratio = 1.0;  // RMS(measured − commanded at the lag) / RMS(commanded), moving samples
  double cmd_rms_mps2 = 0.0;
  double residual_rms_mps2 = 0.0;
  std::size_t moving_samples = 0;  // at the decimated rate
};

struct LagOptions {
  double min_lag_s = -0.3, max_lag_s = 0.3;  // search range
  double rate_hz = 1000.0;                   // decimated rate of the correlation
  double moving_fraction = 0.05;             // |a_cmd| above this share of its maximum is motion
};

// cmd and meas on one sample clock (fs_hz), same length.
LagEstimate estimate_lag(const std::vector<Eigen::Vector3d>& cmd_mps2, const std::vector<Eigen::Vector3d>& meas_mps2,
                         double fs_hz, const LagOptions& options = {});

}  // namespace eical::dsp::align
