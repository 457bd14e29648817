#include "tools/io/csv_inputs.hpp"

#include "tools/io/csv_table.hpp"

#include <map>

namespace eical::tools {

dsp::comp::ErrorCurve read_error_curve_csv(const std::string& file) {
  const CsvTable t(file, {"pos_mm", "error_um"});
  dsp::comp::ErrorCurve c;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    c.pos_mm.push_back(t.number(r, "pos_mm"));
    c.error_um.push_back(t.number(r, "error_um"));
  }
  return c;
}

std::vector<dsp::comp::AngleSeries> read_angle_series_csv(const std::string& file) {
  const CsvTable t(file, {"angle_deg", "deviation_arcsec", "series"});
  std::map<std::string, dsp::comp::AngleSeries> by_name;
  std::vector<std::string> order;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    const std::string& name = t.text(r, "series");
    if (!by_name.count(name)) order.push_back(name), by_name[name].name = name;
    by_name[name].angle_deg.push_back(t.number(r, "angle_deg"));
    by_name[name].deviation_arcsec.push_back(t.number(r, "deviation_arcsec"));
  }
  std::vector<dsp::comp::AngleSeries> series;
  for (const auto& n : order) series.push_back(by_name[n]);
  return series;
}

std::vector<VolumetricPoint> read_volumetric_points_csv(const std::string& file) {
  const CsvTable p(file, {"x", "y", "z", "xp", "yp", "zp"});
  std::vector<VolumetricPoint> out;
  for (std::size_t r = 0; r < p.rows(); ++r)
    out.push_back({Eigen::Vector3d(p.number(r, "x"), p.number(r, "y"), p.number(r, "z")),
                   Eigen::Vector3d(p.number(r, "xp"), p.number(r, "yp"), p.number(r, "zp"))});
  return out;
}

}  // namespace eical::tools
