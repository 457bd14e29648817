#include "drivers/import/klipper_import.hpp"

#include "drivers/import/capture_files.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::drivers {

ImportResult import_klipper(const std::filesystem::path& file, const KlipperImport& options) {
  const StampedAccel capture = read_klipper_capture(file);
  const UniformClock clock = fit_uniform_clock(capture.t_s, capture.source);
  UniformSeries accel = resample(capture.t_s, capture.accel_mps2, clock);
  for (auto& v : accel.values) v /= options.setup.site.g_mps2;  // in g of the site, as run.toml's [site] says
  const sim::nc::AccelProfileSetPoint sp(sim::nc::klipper_segments(options.test), options.direction, options.start_mm);

  MeasuredSeries measured{clock.fs_hz, clock.t0_s, accel.grid_index, accel.values};
  ReferenceSignal ref;
  ref.t_begin_s = 0.0, ref.t_end_s = sp.duration_s();
  for (int a = 0; a < 3; ++a) ref.moving[a] = std::abs(options.direction[a]) > 1e-12 ? 1.0 : 0.0;
  ref.accel = [&sp](double t) { return sp.at(t).acc_mm_s2; };
  const dsp::SensorSpec spec = import_sensor_spec(options.setup, clock.fs_hz);
  ref.sensor_f0_hz = spec.f0_hz, ref.sensor_zeta = spec.zeta;
  const OffsetEstimate offset = estimate_offset(measured, ref);
  require_alignment(offset, capture.source);

  ImportSetup setup = options.setup;
  double v_max = 0.0;
  for (double t = 0.0; t <= sp.duration_s(); t += 1e-3) v_max = std::max(v_max, sp.at(t).vel_mm_s.norm());
  setup.feed_mm_min = v_max * 60.0;
  ImportSetPoint isp{[&sp](double t) { return sp.at(t).pos_mm; }, 0.0, sp.duration_s(), true};
  ImportResult out{imported_run(clock, accel, setup, isp, offset.offset_s), {}};
  ImportReport& r = out.report;
  r.kind = "klipper";
  r.source = capture.source;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Klipper resonance test (%s executor): %.3g .. %.5g Hz, %.4g mm/s2 per Hz, %.3g Hz/s, sweeping %.4g "
                "mm/s2 / %.3g s, direction [%.4g, %.4g, %.4g], %.3f s",
                options.test.legacy_moves ? "older" : "current", options.test.freq_start_hz, options.test.freq_end_hz,
                options.test.accel_per_hz, options.test.hz_per_sec, options.test.sweeping_accel_mm_s2,
                options.test.sweeping_period_s, sp.direction().x(), sp.direction().y(), sp.direction().z(),
                sp.duration_s());
  r.excitation = buf;
  r.accel_clock = clock;
  r.samples = capture.t_s.size();
  r.offset = offset;
  return out;
}

}  // namespace eical::drivers
