#include "drivers/import/capture_export.hpp"

#include "dsp/core/error.hpp"

#include <cmath>

namespace eical::drivers {

StampedAccel exported_capture(const dsp::Run& run, const sim::JitteredCapture& jittered,
                              const sim::CaptureSamples& samples, const sim::CaptureClock& clock, int part,
                              const std::string& source) {
  if (part != 0 && part != 1) throw dsp::InputError("export: the sensor must be the table's or the head's");
  if (!run.meta.sensor_present[part])
    throw dsp::InputError(std::string("export: the run has no ") + (part ? "head" : "table") + " sensor");
  if (jittered.counts.size() != run.frames.size() || samples.jitter_s.size() != run.frames.size())
    throw dsp::InputError("export: the capture does not match the run's frames");
  const auto& acq = run.meta.acquisition;
  const dsp::SensorSpec& spec = run.meta.sensors[part];
  StampedAccel out;
  out.source = source;
  for (std::size_t n = 0; n < run.frames.size(); ++n) {
    if (!samples.kept[n]) continue;
    Eigen::Vector3d a_mps2;
    for (int a = 0; a < 3; ++a)
      a_mps2[a] =
          static_cast<double>(jittered.counts[n][static_cast<std::size_t>(3 * part + a)] - acq.adc_offset_counts) *
          acq.adc_lsb_volt / spec.k1_v_per_g[a] * run.meta.site.g_mps2;
    out.t_s.push_back(samples.stamp_s(n, acq.fs_hz, clock));
    out.accel_mps2.push_back(a_mps2);
  }
  return out;
}

NcTrace exported_nc_trace(const sim::nc::SetPoint& set_point, double period_s, double nc_offset_s,
                          const std::string& source) {
  if (!(period_s > 0.0)) throw dsp::InputError("export: the servo period must be positive");
  NcTrace out;
  out.source = source;
  const auto first = static_cast<std::int64_t>(std::ceil(nc_offset_s / period_s));
  const auto last = static_cast<std::int64_t>(std::floor((set_point.duration_s() + nc_offset_s) / period_s));
  for (std::int64_t k = first; k <= last; ++k) {
    const double t_nc = static_cast<double>(k) * period_s;
    out.t_s.push_back(t_nc);
    out.pos_mm.push_back(set_point.at(t_nc - nc_offset_s).pos_mm);
  }
  return out;
}

}  // namespace eical::drivers
