#pragma once
// The command line's small CSV inputs (read through CsvTable: every error names the file,
// line and column): lincomp's error curve, fourier's angle series, volumetric's points.
#include "dsp/comp/fourier.hpp"
#include "dsp/comp/lincomp.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace eical::tools {

// pos_mm,error_um (error = actual − nominal).
dsp::comp::ErrorCurve read_error_curve_csv(const std::string& file);

// angle_deg,deviation_arcsec,series: one AngleSeries per series name, in order of appearance.
std::vector<dsp::comp::AngleSeries> read_angle_series_csv(const std::string& file);

// x,y,z,xp,yp,zp in mm: a position and the tool offset at it.
struct VolumetricPoint {
  Eigen::Vector3d x_mm, tool_mm;
};
std::vector<VolumetricPoint> read_volumetric_points_csv(const std::string& file);

}  // namespace eical::tools
