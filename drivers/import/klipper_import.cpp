#include "drivers/import/klipper_import.hpp"

#include "drivers/import/capture_files.hpp"
#include "drivers/import/shaketune_file.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::drivers {
namespace {

// The test ends where it starts, so the capture's mean is the sensor's reading at rest:
// gravity. A capture whose scale or axes map contradicts it (or the motion) is refused with
// the fix, before explain would read a wrong scale as the machine's or a turned axis as a
// misalignment.
MountingCheck check_capture_mounting(const UniformSeries& accel_g, const OffsetEstimate& offset,
                                     const KlipperImport& options) {
  Eigen::Vector3d mean_g = Eigen::Vector3d::Zero();
  for (const auto& v : accel_g.values) mean_g += v;
  if (!accel_g.values.empty()) mean_g /= static_cast<double>(accel_g.values.size());
  MountingCheck c = check_mounting(mean_g, offset.gain, options.setup.to_machine, options.direction.normalized());
  if (c.consistent) return c;
  std::string why;
  for (const auto& f : c.findings) why += "; " + f;
  throw dsp::InputError("import klipper: the capture contradicts its stated scale or mounting" + why);
}

// Klipper records the whole test: the capture starts before it and ends after it. A test
// that the alignment puts mostly outside the capture (a short capture matched to a stretch
// of a long sweep) is not this capture's test, however well the stretch correlates.
constexpr double kMinTestInsideCapture = 0.95;

void require_test_inside_capture(const UniformClock& clock, const OffsetEstimate& offset, double test_s,
                                 const std::string& source) {
  const double capture_begin_s = clock.time_at(0), capture_end_s = clock.time_at(clock.index.back());
  const double test_begin_s = offset.offset_s, test_end_s = offset.offset_s + test_s;
  const double inside_s = std::max(0.0, std::min(capture_end_s, test_end_s) - std::max(capture_begin_s, test_begin_s));
  if (test_s > 0.0 && inside_s >= kMinTestInsideCapture * test_s) return;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                ": the capture spans %.2f s, the resonance test %.2f s; aligned at its best offset (%.3f s, the "
                "command explaining %.1f %% of the measured), %.1f %% of the test lies inside the capture, %.0f %% "
                "needed: not this capture's test (other test parameters, or a capture of something else)",
                capture_end_s - capture_begin_s, test_s, offset.offset_s, 100.0 * offset.explained,
                100.0 * inside_s / test_s, 100.0 * kMinTestInsideCapture);
  throw dsp::InputError(source + buf);
}

}  // namespace

ImportResult import_klipper(const std::filesystem::path& file, const KlipperImport& options) {
  return import_klipper_capture(read_klipper_capture(file), options);
}

ImportResult import_shaketune(const std::filesystem::path& file, const std::string& measurement,
                              const KlipperImport& options) {
  const auto measurements = read_shaketune_stdata(file);
  ImportResult r = import_klipper_capture(pick_measurement(measurements, measurement, file.string()).capture, options);
  r.report.kind = "shaketune";
  return r;
}

ImportResult import_klipper_capture(const StampedAccel& capture, const KlipperImport& options) {
  const UniformClock clock = fit_uniform_clock(capture.t_s, capture.source);
  UniformSeries accel = resample(capture.t_s, capture.accel_mps2, clock);
  // In g of the site, as run.toml's [site] says, times what the recorder's constants were off by.
  for (auto& v : accel.values) v *= options.setup.accel_scale / options.setup.site.g_mps2;
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
  require_test_inside_capture(clock, offset, sp.duration_s(), capture.source);
  const MountingCheck mounting = check_capture_mounting(accel, offset, options);

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
  r.accel_scale = options.setup.accel_scale;
  r.mounting = mounting;
  return out;
}

}  // namespace eical::drivers
