// eical import klipper|shaketune|csv: recordings made by other systems into eical-run/1
// (drivers/import; run-format.md "Runs measured by other systems").
#include "drivers/import/csv_import.hpp"
#include "drivers/import/klipper_import.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/sensor/axes_map.hpp"
#include "sim/sensor/mems_chip.hpp"
#include "tools/commands.hpp"

#include <cstdio>
#include <memory>
#include <sstream>

namespace eical::tools {
namespace {

// What both importers take: where the sensor sits, its chip and mounting, the layout.
struct Common {
  std::string out, id, sensor = "head", chip = "adxl345", mounting = "x,y,z", head_axes = "xy", table_axes = "z";
  double bandwidth_hz = 0.0, noise_ug = -1.0, g_mps2 = drivers::kStandardGravity_mps2, accel_scale = 1.0;
  bool gzip = false, overwrite = false;
};

void add_common(CLI::App* cmd, Common& c) {
  cmd->add_option("-o,--out", c.out, "run directory to write")->required();
  cmd->add_option("--id", c.id, "run id (default: the directory's name)");
  cmd->add_option("--sensor", c.sensor, "the part that carries the sensor: head or table")
      ->default_val("head")
      ->check(CLI::IsMember({"head", "table"}));
  std::vector<std::string> chips;
  for (const auto& chip : sim::mems_chips()) chips.push_back(chip.name);
  cmd->add_option("--chip", c.chip,
                  "the sensor's chip (noise density and low-pass corner of its data sheet, sim/sensor/mems_chip.hpp)")
      ->default_val("adxl345")
      ->check(CLI::IsMember(chips));
  cmd->add_option("--bandwidth-hz", c.bandwidth_hz,
                  "the chip's low-pass corner, Hz (default: the chip's at the capture's rate)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--noise-ug-per-rthz", c.noise_ug,
                  "noise density, ug/sqrt(Hz), two-sided as run-format.md (default: the chip's data sheet / sqrt(2))")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--mounting", c.mounting,
                  "the sensor's axes as machine axes, Klipper axes_map notation (x,y,z; -y,x,z ...): machine X, Y, Z "
                  "are the named columns of the file")
      ->default_val("x,y,z");
  cmd->add_option("--head-axes", c.head_axes, "machine axes the head moves")->default_val("xy");
  cmd->add_option("--table-axes", c.table_axes, "machine axes the table moves")->default_val("z");
  cmd->add_option("--g-mps2", c.g_mps2,
                  "gravity at the site, m/s2: converts the recorded acceleration to g (run.toml [site]; default "
                  "standard gravity)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--accel-scale", c.accel_scale,
                  "multiply the recorded acceleration by this (a recorder that converted one chip's counts with "
                  "another's constants; import klipper names the factor gravity shows)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--gzip", c.gzip, "write samples.csv.gz");
  cmd->add_flag("--overwrite", c.overwrite, "replace an existing run");
}

drivers::ImportSetup setup_of(const Common& c) {
  drivers::ImportSetup s;
  s.id = c.id.empty() ? std::filesystem::path(c.out).filename().string() : c.id;
  s.part = c.sensor == "head" ? 1 : 0;
  s.chip = c.chip;
  s.bandwidth_hz = c.bandwidth_hz;
  s.noise_ug_per_rthz = c.noise_ug;
  s.to_machine = sim::axes_map_matrix(c.mounting, "--mounting");
  s.machine.name = "imported";
  s.machine.head_axes = drivers::axis_list(c.head_axes, "--head-axes");
  s.machine.table_axes = drivers::axis_list(c.table_axes, "--table-axes");
  s.site.g_mps2 = c.g_mps2;
  s.accel_scale = c.accel_scale;
  return s;
}

void finish(const Common& c, const drivers::ImportResult& r) {
  drivers::write_run(r.run, c.out, {.gzip = c.gzip, .overwrite = c.overwrite});
  drivers::write_import_report(c.out, r.report);
  const auto& k = r.report.accel_clock;
  const auto& off = r.report.offset;
  std::printf(
      "wrote %s: %zu frames at %.6g Hz (median dt %.2f us, jitter %.2f us rms, %zu lost frames in %zu gaps), one "
      "sensor (%s)\n",
      c.out.c_str(), r.run.frames.size(), k.fs_hz, k.median_dt_s * 1e6, k.jitter_rms_s * 1e6, k.lost_frames, k.gaps,
      c.sensor.c_str());
  std::printf(
      "time offset recorder - set-point: %.6f s +- %.1f us (k=1: block jackknife of %d, and %.1f us for the response "
      "beyond the excited band), commanded acceleration explains %.1f %% of the measured\n",
      off.offset_s, off.u_s * 1e6, off.blocks, off.u_extension_s * 1e6, 100.0 * off.explained);
  // Where the commanded motion shows, through the stated mounting: a wrong --mounting or
  // --axis shows here (eical explain names it as sensor.misalignment).
  const Eigen::Vector3d moved =
      (r.run.meta.sensors[r.run.meta.sensor_present[1] ? 1 : 0].to_machine * off.gain).colwise().norm().transpose();
  const int axis = static_cast<int>(std::max_element(moved.data(), moved.data() + 3) - moved.data());
  const Eigen::Vector3d seen = r.run.meta.sensors[r.run.meta.sensor_present[1] ? 1 : 0].to_machine * off.gain.col(axis);
  std::printf(
      "commanded %c shows in the measured acceleration along machine [%.3f, %.3f, %.3f] (stated mounting), gain %.4g g "
      "per mm/s2\n",
      static_cast<char>('x' + axis), seen.x() / seen.norm(), seen.y() / seen.norm(), seen.z() / seen.norm(),
      seen.norm());
  if (r.report.mounting) {
    std::printf("gravity at rest: %.3f g; the stated mounting %s %s\n", r.report.mounting->gravity_g,
                r.report.mounting->stated_map.c_str(),
                r.report.mounting->consistent ? "fits it and the motion" : "does not fit");
    for (const auto& f : r.report.mounting->findings) std::printf("  %s\n", f.c_str());
  }
  if (r.report.nc_clock)
    std::printf("NC trace: %.6g Hz, jitter %.2f us rms, %zu lost samples bridged\n", r.report.nc_clock->fs_hz,
                r.report.nc_clock->jitter_rms_s * 1e6, r.report.nc_clock->lost_frames);
  std::printf("import.toml records the clock, the resampling and the offset\n");
}

// Klipper's resonance test as it ran: what both Klipper's capture and Shake&Tune's file need.
struct KlipperOpt {
  Common c;
  std::string axis = "x";
  bool legacy = false;
  double freq_start = 0.0, freq_end = 0.0, accel_per_hz = 0.0, hz_per_sec = 0.0, sweeping_accel = -1.0,
         sweeping_period = -1.0, max_accel = 0.0;
  std::vector<double> start{0.0, 0.0, 0.0};
};

void add_klipper_test_options(CLI::App* cmd, KlipperOpt& o) {
  cmd->add_option("--axis", o.axis, "the test's AXIS: x, y or dx,dy (as TEST_RESONANCES)")->default_val("x");
  cmd->add_flag("--klipper-legacy", o.legacy,
                "older Klipper: max_freq 133.33 Hz, accel_per_hz 75, no sweeping, moves out and back");
  cmd->add_option("--freq-start", o.freq_start, "FREQ_START, Hz (default 5)");
  cmd->add_option("--freq-end", o.freq_end, "FREQ_END, Hz (default 200; legacy 133.33)");
  cmd->add_option("--accel-per-hz", o.accel_per_hz, "accel_per_hz, mm/s2 per Hz (default 60; legacy 75)");
  cmd->add_option("--hz-per-sec", o.hz_per_sec, "hz_per_sec (default 1)");
  cmd->add_option("--sweeping-accel", o.sweeping_accel, "sweeping_accel, mm/s2 (default 400; legacy none)");
  cmd->add_option("--sweeping-period", o.sweeping_period, "sweeping_period, s (default 1.2; 0: no sweeping)");
  cmd->add_option("--max-accel", o.max_accel, "the printer's max_accel, mm/s2: the stop after a sweep (default 5000)");
  cmd->add_option("--start", o.start, "where the test starts, mm (Klipper's probe point)")->expected(3)->delimiter(',');
  add_common(cmd, o.c);
}

drivers::KlipperImport klipper_import_of(const KlipperOpt& o) {
  drivers::KlipperImport k;
  k.test = o.legacy ? sim::nc::KlipperTest::legacy() : sim::nc::KlipperTest::current();
  if (o.freq_start > 0.0) k.test.freq_start_hz = o.freq_start;
  if (o.freq_end > 0.0) k.test.freq_end_hz = o.freq_end;
  if (o.accel_per_hz > 0.0) k.test.accel_per_hz = o.accel_per_hz;
  if (o.hz_per_sec > 0.0) k.test.hz_per_sec = o.hz_per_sec;
  if (o.sweeping_accel >= 0.0) k.test.sweeping_accel_mm_s2 = o.sweeping_accel;
  if (o.sweeping_period >= 0.0) k.test.sweeping_period_s = o.sweeping_period;
  if (o.max_accel > 0.0) k.test.stop_accel_mm_s2 = o.max_accel;
  k.direction = sim::nc::test_direction(o.axis, "--axis");
  k.start_mm = Eigen::Vector3d(o.start[0], o.start[1], o.start[2]);
  k.setup = setup_of(o.c);
  return k;
}

void register_klipper(CLI::App* import) {
  struct CaptureOpt {
    KlipperOpt k;
    std::string capture;
  };
  auto o = std::make_shared<CaptureOpt>();
  auto* cmd = import->add_subcommand(
      "klipper",
      "A Klipper raw accelerometer capture (#time,accel_x,accel_y,accel_z; print time, mm/s2) of TEST_RESONANCES; "
      "the set-point from Klipper's resonance_tester.py, its start found by cross-correlation");
  cmd->add_option("capture", o->capture, "the capture (raw_data_*.csv)")->required();
  add_klipper_test_options(cmd, o->k);
  cmd->callback([o] { finish(o->k.c, drivers::import_klipper(o->capture, klipper_import_of(o->k))); });
}

void register_shaketune(CLI::App* import) {
  struct StdataOpt {
    KlipperOpt k;
    std::string file, measurement;
  };
  auto o = std::make_shared<StdataOpt>();
  auto* cmd = import->add_subcommand(
      "shaketune",
      "A measurement of Shake&Tune's .stdata file (K-ShakeTune: zstd JSON lines of Klipper's samples); the "
      "set-point from Klipper's generator the plugin drives, as for import klipper (its raw CSVs: import klipper)");
  cmd->add_option("file", o->file, "the .stdata file")->required();
  cmd->add_option("--measurement", o->measurement,
                  "the measurement's name (the file's only one when left out; a belt or axes test holds two)");
  add_klipper_test_options(cmd, o->k);
  cmd->callback([o] { finish(o->k.c, drivers::import_shaketune(o->file, o->measurement, klipper_import_of(o->k))); });
}

// "a,b,c" → three names.
std::array<std::string, 3> three(const std::string& list, const std::string& what) {
  std::array<std::string, 3> out;
  std::stringstream ss(list);
  for (auto& s : out)
    if (!std::getline(ss, s, ',') || s.empty())
      throw dsp::InputError(what + ": '" + list + "' must name three columns");
  std::string extra;
  if (std::getline(ss, extra)) throw dsp::InputError(what + ": '" + list + "' must name three columns");
  return out;
}

void register_csv(CLI::App* import) {
  struct CsvOpt {
    Common c;
    std::string accel, nc, time_col, columns, unit = "mps2", time_unit = "s", nc_format = "halsampler", nc_time_col,
                                              nc_columns;
    std::vector<std::string> ignore, nc_ignore;
    double servo_period_s = 0.001;
  };
  auto o = std::make_shared<CsvOpt>();
  auto* cmd = import->add_subcommand(
      "csv",
      "A generic accelerometer CSV plus an NC trace (LinuxCNC halsampler or a CSV servo trace); both onto one "
      "uniform clock, their offset found by cross-correlation");
  cmd->add_option("--accel", o->accel, "accelerometer CSV with a header row")->required();
  cmd->add_option("--time-col", o->time_col, "its time column (default: the first)");
  cmd->add_option("--columns", o->columns,
                  "its three acceleration columns, sensor axes 1..3 (default: the three after the time)");
  cmd->add_option("--ignore-cols", o->ignore,
                  "its columns that are not to be read (any other unread column is refused; ext_* columns are "
                  "always skipped)")
      ->delimiter(',');
  cmd->add_option("--unit", o->unit, "acceleration unit: mps2, mmps2 or g")
      ->default_val("mps2")
      ->check(CLI::IsMember({"mps2", "mmps2", "g"}));
  cmd->add_option("--time-unit", o->time_unit, "time unit of both files' time columns: s, ms or us")
      ->default_val("s")
      ->check(CLI::IsMember({"s", "ms", "us"}));
  cmd->add_option("--nc", o->nc, "NC trace of the commanded position")->required();
  cmd->add_option("--nc-format", o->nc_format,
                  "halsampler (<n> Xcmd Ycmd Zcmd Xfb Yfb Zfb marker) or csv (header; time, x, y, z)")
      ->default_val("halsampler")
      ->check(CLI::IsMember({"halsampler", "csv"}));
  cmd->add_option("--servo-period-s", o->servo_period_s,
                  "halsampler: the servo thread's period, s ([EMCMOT]SERVO_PERIOD)")
      ->default_val(0.001)
      ->check(CLI::PositiveNumber);
  cmd->add_option("--nc-time-col", o->nc_time_col, "csv NC trace: its time column (default: the first)");
  cmd->add_option("--nc-columns", o->nc_columns,
                  "csv NC trace: its x, y, z columns, mm (default: the three after the time)");
  cmd->add_option("--nc-ignore-cols", o->nc_ignore, "csv NC trace: its columns that are not to be read")
      ->delimiter(',');
  add_common(cmd, o->c);
  cmd->callback([o] {
    drivers::CsvImport k;
    const double time_scale = o->time_unit == "s" ? 1.0 : (o->time_unit == "ms" ? 1e-3 : 1e-6);
    k.accel_columns.time = o->time_col, k.accel_columns.time_scale_s = time_scale;
    if (!o->columns.empty()) k.accel_columns.values = three(o->columns, "--columns");
    k.accel_columns.ignored = o->ignore;
    k.unit = o->unit == "mps2" ? drivers::AccelUnit::mps2
                               : (o->unit == "mmps2" ? drivers::AccelUnit::mmps2 : drivers::AccelUnit::g);
    k.nc_halsampler = o->nc_format == "halsampler";
    k.servo_period_s = o->servo_period_s;
    k.nc_columns.time = o->nc_time_col, k.nc_columns.time_scale_s = time_scale;
    if (!o->nc_columns.empty()) k.nc_columns.values = three(o->nc_columns, "--nc-columns");
    k.nc_columns.ignored = o->nc_ignore;
    k.setup = setup_of(o->c);
    finish(o->c, drivers::import_csv(o->accel, o->nc, k));
  });
}

}  // namespace

void register_import(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "import",
      "Recordings made by other systems into eical-run/1 (one sensor, set-point reconstructed, time offset estimated)");
  cmd->require_subcommand(1);
  register_klipper(cmd);
  register_shaketune(cmd);
  register_csv(cmd);
}

}  // namespace eical::tools
