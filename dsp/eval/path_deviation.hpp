#pragma once
// Free-form test (cross-grid encoder practice): the deviation of the measured path from
// the commanded path, for any path. Each measured point is compared with the closest
// point of the commanded polyline (searched near the point of the same sample, so that
// a path crossing itself is not matched to the wrong pass); the deviation is split into
// the part normal to the path (contour error, what the workpiece sees) and the part
// along it (lag, which does not spoil the contour).
#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace eical::dsp::eval {

struct PathDeviationOptions {
  double search_window_s = 0.2;  // how far (in time) from the same sample the match may lie
  double min_speed_mm_s = 0.5;   // slower samples (rest, reversal) have no defined normal
};

struct PathDeviation {
  std::vector<double> arc_length_mm;        // along the commanded path, per evaluated sample
  std::vector<double> normal_um;            // signed by the side: positive left of the travel direction (xy)
  std::vector<double> normal_magnitude_um;  // |normal component| (3-D)
  std::vector<double> tangential_um;        // positive = ahead of the set-point
  std::vector<std::size_t> sample;          // which input sample each entry came from
  double contour_error_max_um = 0.0;        // max |normal|
  double contour_error_rms_um = 0.0;
  double tangential_rms_um = 0.0;
};

// cmd and meas on one sample clock (mm, machine axes). Throws InputError on mismatched
// lengths, non-finite values or a path that never moves.
PathDeviation path_deviation(const std::vector<Eigen::Vector3d>& cmd_mm, const std::vector<Eigen::Vector3d>& meas_mm,
                             double fs_hz, const PathDeviationOptions& options = {});

}  // namespace eical::dsp::eval
