#include "dsp/uncertainty/rest_noise_check.hpp"

#include <cmath>
#include <cstdio>

namespace eical::dsp::uncertainty {

double datasheet_relative_noise(const SensorSpec sensors[2]) {
  return std::hypot(sensors[0].noise_ug_per_rthz, sensors[1].noise_ug_per_rthz);
}

namespace {

double rms(const Eigen::Vector3d& v) { return std::sqrt(v.squaredNorm() / 3.0); }

}  // namespace

std::optional<Flag> noise_disagreement(const RestNoise& measured, double datasheet_ug_rthz,
                                       const DatasheetTolerance& tolerance) {
  if (!measured.measured() || !(datasheet_ug_rthz > 0.0)) return std::nullopt;
  const double n = rms(measured.density_ug_rthz), ratio = n / datasheet_ug_rthz;
  // Outside the data sheet's spread by more than twice the estimate's own uncertainty.
  const double slack = 2.0 * measured.relative_u();
  const double lo = (1.0 - tolerance.noise_density_relative) * (1.0 - slack),
               hi = (1.0 + tolerance.noise_density_relative) * (1.0 + slack);
  if (ratio >= lo && ratio <= hi) return std::nullopt;
  char b[320];
  std::snprintf(b, sizeof b,
                "head − table's white noise measured at rest is %.3f µg/√Hz (x %.3f, y %.3f, z %.3f; "
                "%zu Allan clusters of %.0f ms), %s the data sheet's %.3f (%.3f–%.3f): the uncertainty uses the "
                "measured one",
                n, measured.density_ug_rthz.x(), measured.density_ug_rthz.y(), measured.density_ug_rthz.z(),
                measured.differences, measured.tau_s * 1000.0, ratio > 1.0 ? "above" : "below", datasheet_ug_rthz,
                datasheet_ug_rthz * (1.0 - tolerance.noise_density_relative),
                datasheet_ug_rthz * (1.0 + tolerance.noise_density_relative));
  return Flag{FlagCode::noise_density, {}, b};
}

std::string noise_source_text(const RestNoise& measured, double datasheet_ug_rthz) {
  char b[200];
  if (measured.measured())
    std::snprintf(b, sizeof b, "white noise %.3f µg/√Hz measured at rest (%.1f s, ±%.0f %%; data sheet %.3f)",
                  rms(measured.density_ug_rthz), measured.quiet_s, 100.0 * measured.relative_u(), datasheet_ug_rthz);
  else
    std::snprintf(b, sizeof b, "white noise %.3f µg/√Hz from the data sheet (no rest long enough to measure it)",
                  datasheet_ug_rthz);
  return b;
}

}  // namespace eical::dsp::uncertainty
