#include "dsp/comp/volumetric.hpp"

#include "dsp/comp/lincomp.hpp"
#include "dsp/core/error.hpp"

#include <Eigen/Dense>

#include <cmath>

namespace eical::dsp::comp {
namespace {

enum C { xtx, xty, xtz, xrx, xry, xrz, ytx, yty, ytz, yrx, yry, yrz, ztx, zty, ztz, zrx, zry, zrz };

}  // namespace

void validate(const VolumetricModel& model) {
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a)
    // min == max: the model describes the axis where it stood (a fit from runs that never moved it).
    if (!(model.range_mm[a][0] <= model.range_mm[a][1]) || !std::isfinite(model.range_mm[a][0]) ||
        !std::isfinite(model.range_mm[a][1]))
      throw InputError(std::string("volumetric: axis ") + axes[a] + " range must be [min, max] with min <= max");
  for (double w : {model.xwy_urad, model.xwz_urad, model.ywz_urad})
    if (!std::isfinite(w)) throw InputError("volumetric: squareness must be finite");
  for (int k = 0; k < 18; ++k) {
    const auto& t = model.component[k];
    const std::string name = kVolumetricComponents[k];
    if (t.pos_mm.empty()) throw InputError("volumetric: component '" + name + "' is missing");
    if (t.pos_mm.size() != t.values.size())
      throw InputError("volumetric: component '" + name + "': positions and values differ in count");
    for (std::size_t i = 0; i < t.pos_mm.size(); ++i) {
      if (!std::isfinite(t.pos_mm[i]) || !std::isfinite(t.values[i]))
        throw InputError("volumetric: component '" + name + "': support point " + std::to_string(i + 1) +
                         " is not finite");
      if (i > 0 && t.pos_mm[i] <= t.pos_mm[i - 1])
        throw InputError("volumetric: component '" + name + "': positions must increase strictly (point " +
                         std::to_string(i + 1) + (t.pos_mm[i] == t.pos_mm[i - 1] ? ", duplicate)" : ")"));
    }
    const int a = k / 6;
    if (t.pos_mm.front() > model.range_mm[a][0] + 1e-9 || t.pos_mm.back() < model.range_mm[a][1] - 1e-9)
      throw InputError("volumetric: component '" + name + "' does not cover the axis range [" +
                       std::to_string(model.range_mm[a][0]) + ", " + std::to_string(model.range_mm[a][1]) + "] mm");
  }
}

std::array<double, 18> component_values(const VolumetricModel& model, const Eigen::Vector3d& x_mm) {
  std::array<double, 18> v{};
  for (int k = 0; k < 18; ++k) v[k] = interpolate(model.component[k].pos_mm, model.component[k].values, x_mm[k / 6]);
  return v;
}

VolumetricResult volumetric_deviation(const VolumetricModel& model, const Eigen::Vector3d& x_mm,
                                      const Eigen::Vector3d& tool_mm) {
  VolumetricResult r;
  for (int a = 0; a < 3; ++a)
    if (x_mm[a] < model.range_mm[a][0] || x_mm[a] > model.range_mm[a][1]) {
      r.out_of_range_axis = a;
      return r;  // never extrapolate
    }
  const auto c = component_values(model, x_mm);
  const Eigen::Vector3d eT(c[xtx] + c[ytx] + c[ztx], c[xty] + c[yty] + c[zty], c[xtz] + c[ytz] + c[ztz]);
  Eigen::Matrix3d ER;
  ER << 0.0, -model.xwy_urad - c[xrz], model.xwz_urad + c[xry] + c[yry],  //
      0.0, 0.0, -model.ywz_urad - c[xrx] - c[yrx],                        //
      0.0, c[xrx], 0.0;
  const double rx = c[xrx] + c[yrx] + c[zrx], ry = c[xry] + c[yry] + c[zry], rz = c[xrz] + c[yrz] + c[zrz];
  Eigen::Matrix3d EP;
  EP << 0.0, -rz, ry,  //
      rz, 0.0, -rx,    //
      -ry, rx, 0.0;
  // µrad · mm = nm → µm.
  r.e_um = eT + (ER * x_mm + EP * tool_mm) * 1e-3;
  return r;
}

}  // namespace eical::dsp::comp
