#pragma once
// The measured acceleration against the set-point's, band-limited below the structure's
// modes: what a run without a rest or a position support can still show (run-format.md,
// "No standstill"). a_meas ≈ G · a_cmd(t − τ) + b, with G the 3 × 3 gain of the moving
// axes (mounting, scale), τ the lag and b the bias (gravity included), each with its
// block-jackknife standard error.
#include "dsp/model/run_residuals.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>

namespace eical::dsp::model {

struct AccelerationComparison {
  bool valid = false;
  std::string why;              // when not valid
  double cutoff_hz = 0.0;       // the band compared: below this
  std::array<bool, 3> input{};  // commanded axes with acceleration in the band
  Eigen::Matrix3d gain = Eigen::Matrix3d::Zero(),
                  gain_sigma = Eigen::Matrix3d::Zero();  // measured row per commanded column
  Eigen::Vector3d bias_mm_s2 = Eigen::Vector3d::Zero(), bias_sigma_mm_s2 = Eigen::Vector3d::Zero();
  double lag_s = 0.0, lag_sigma_s = 0.0;
  double explained_fraction = 0.0;  // of the measured band-limited variance on the moving axes
  int blocks = 0;
};

// `cutoff_hz`: the band's upper end (below the lowest mode); the lag is searched within
// ±max_lag_s.
AccelerationComparison compare_accelerations(const RunResiduals& rr, double cutoff_hz, double max_lag_s = 0.1);

// A mounting other than run.toml's: a sign flip, swapped axes or a mirror, from G's columns
// on the moving axes. `to_machine` is the mounting that fits (axes not moved stay as
// configured, or take the machine axis left over).
struct MountingFit {
  int sensor = 1;  // 0 table, 1 head
  Eigen::Matrix3d to_machine = Eigen::Matrix3d::Identity();
  std::string axes_map;  // to_machine = map · run.toml's (Klipper's notation), e.g. "-x,y,z"
  std::string evidence;
};
std::optional<MountingFit> gross_mounting(const RunResiduals& rr, const AccelerationComparison& c);

}  // namespace eical::dsp::model
