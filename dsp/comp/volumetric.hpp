#pragma once
// 21-parameter volumetric error model of a three-axis Cartesian machine (seed 004, the
// model PTB tested the AfM correction library against; Busch, Kunzmann, Wäldele 1985):
//   e = e_T + E_R · x + E_P · x_P
// for the chain X → Y → Z (Y rides on X, Z on Y), with the 18 error functions of the axes
// (xtx … zrz: translations in µm, rotations in µrad) given as support tables over each
// axis' range (linear interpolation) and the squareness constants xwy, xwz, ywz (µrad).
// Positions x and the tool offset x_P in mm. A position outside an axis' described
// range is reported, never extrapolated.
#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace eical::dsp::comp {

// The 18 error functions in a fixed order: axis (x, y, z) × (tx, ty, tz, rx, ry, rz).
inline constexpr std::array<const char*, 18> kVolumetricComponents = {"xtx", "xty", "xtz", "xrx", "xry", "xrz",
                                                                      "ytx", "yty", "ytz", "yrx", "yry", "yrz",
                                                                      "ztx", "zty", "ztz", "zrx", "zry", "zrz"};

struct SupportTable {
  std::vector<double> pos_mm;  // strictly increasing, covering the axis range
  std::vector<double> values;  // µm (t) or µrad (r)
};

struct VolumetricModel {
  std::array<std::array<double, 2>, 3> range_mm{};  // [axis][min, max]
  double xwy_urad = 0.0, xwz_urad = 0.0, ywz_urad = 0.0;
  std::array<SupportTable, 18> component;  // in kVolumetricComponents order
};

// Checks ranges, tables (monotone, finite, covering the range); InputError naming the component.
void validate(const VolumetricModel& model);

struct VolumetricResult {
  Eigen::Vector3d e_um = Eigen::Vector3d::Zero();
  int out_of_range_axis = -1;  // 0..2 when the position is outside that axis' range
  [[nodiscard]] bool ok() const { return out_of_range_axis < 0; }
};

VolumetricResult volumetric_deviation(const VolumetricModel& model, const Eigen::Vector3d& x_mm,
                                      const Eigen::Vector3d& tool_mm);

// The 18 component values at a position (µm / µrad), in kVolumetricComponents order.
std::array<double, 18> component_values(const VolumetricModel& model, const Eigen::Vector3d& x_mm);

}  // namespace eical::dsp::comp
