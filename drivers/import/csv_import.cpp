#include "drivers/import/csv_import.hpp"

#include "dsp/core/error.hpp"
#include "sim/nc/sampled_set_point.hpp"

#include <algorithm>
#include <cmath>

namespace eical::drivers {

ImportResult import_csv(const std::filesystem::path& accel_file, const std::filesystem::path& nc_file,
                        const CsvImport& options) {
  const StampedAccel capture = read_accel_csv(accel_file, options.accel_columns, options.unit);
  const NcTrace nc = options.nc_halsampler ? read_halsampler(nc_file, options.servo_period_s)
                                           : read_nc_csv(nc_file, options.nc_columns);
  const UniformClock clock = fit_uniform_clock(capture.t_s, capture.source);
  UniformSeries accel = resample(capture.t_s, capture.accel_mps2, clock);
  // In g of the site, as run.toml's [site] says, times what the recorder's constants were off by.
  for (auto& v : accel.values) v *= options.setup.accel_scale / options.setup.site.g_mps2;
  const UniformClock nc_clock = fit_uniform_clock(nc.t_s, nc.source);
  const std::vector<Eigen::Vector3d> nc_uniform = bridge_gaps(nc.t_s, nc.pos_mm, nc_clock);
  const std::size_t n_nc = nc_uniform.size();
  const sim::nc::SampledSetPoint sp(nc_uniform, nc_clock.fs_hz, {}, nc_clock.t0_s);

  MeasuredSeries measured{clock.fs_hz, clock.t0_s, accel.grid_index, accel.values};
  ReferenceSignal ref;
  ref.t_begin_s = nc_clock.t0_s, ref.t_end_s = sp.duration_s();
  Eigen::Vector3d lo = nc_uniform.front(), hi = nc_uniform.front();
  for (const auto& p : nc_uniform) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (int a = 0; a < 3; ++a)
    ref.moving[a] = hi[a] - lo[a] > 1e-3 ? 1.0 : 0.0;  // axes that move more than a micrometre
  if (ref.moving.sum() == 0.0)
    throw dsp::InputError(nc.source + ": the NC trace does not move (nothing to align the clocks with)");
  ref.accel = [&sp](double t) { return sp.at(t).acc_mm_s2; };
  const dsp::SensorSpec spec = import_sensor_spec(options.setup, clock.fs_hz);
  ref.sensor_f0_hz = spec.f0_hz, ref.sensor_zeta = spec.zeta;
  const OffsetEstimate offset = estimate_offset(measured, ref);
  require_alignment(offset, capture.source);

  ImportSetup setup = options.setup;
  double v_max = 0.0;
  for (std::size_t i = 0; i < n_nc; ++i)
    v_max = std::max(v_max, sp.at(nc_clock.time_at(static_cast<std::int64_t>(i))).vel_mm_s.norm());
  setup.feed_mm_min = v_max * 60.0;
  ImportSetPoint isp{[&sp](double t) { return sp.at(t).pos_mm; }, nc_clock.t0_s, sp.duration_s(), false};
  ImportResult out{imported_run(clock, accel, setup, isp, offset.offset_s), {}};
  ImportReport& r = out.report;
  r.kind = "csv";
  r.source = capture.source;
  r.nc_source = nc.source;
  r.excitation = options.nc_halsampler ? "NC trace (LinuxCNC halsampler), natural cubic spline"
                                       : "NC trace (CSV), natural cubic spline";
  r.accel_clock = clock;
  r.nc_clock = nc_clock;
  r.samples = capture.t_s.size();
  r.offset = offset;
  r.accel_scale = options.setup.accel_scale;
  return out;
}

}  // namespace eical::drivers
