#include "drivers/import/imported_run.hpp"

#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/sensor/mems_chip.hpp"

#include <cmath>
#include <cstdio>

namespace eical::drivers {

dsp::SensorSpec import_sensor_spec(const ImportSetup& setup, double fs_hz) {
  dsp::SensorSpec spec = sim::mems_sensor_spec(sim::mems_chip(setup.chip), fs_hz);
  if (setup.bandwidth_hz > 0.0) spec.f0_hz = setup.bandwidth_hz;
  if (setup.noise_ug_per_rthz >= 0.0) spec.noise_ug_per_rthz = setup.noise_ug_per_rthz;
  spec.to_machine = setup.to_machine;
  return spec;
}

dsp::Run imported_run(const UniformClock& clock, const UniformSeries& accel_g, const ImportSetup& setup,
                      const ImportSetPoint& set_point, double offset_s) {
  if (accel_g.values.empty() || accel_g.values.size() != accel_g.grid_index.size())
    throw dsp::InputError("import: no samples");
  if (setup.part != 0 && setup.part != 1) throw dsp::InputError("import: the sensor must be on the table or the head");
  dsp::Run run;
  dsp::RunMeta& m = run.meta;
  m.id = setup.id;
  m.acquisition.fs_hz = clock.fs_hz;
  m.acquisition.adc_bits = 32;
  m.acquisition.adc_lsb_volt = 1.0 / kImportCountsPerG;  // with k1 = 1 V/g: 1 count = 1 µg
  m.acquisition.adc_offset_counts = 0;
  m.acquisition.daq_group_delay_samples = 0.0;
  m.site = setup.site;
  m.machine = setup.machine;
  const dsp::SensorSpec spec = import_sensor_spec(setup, clock.fs_hz);
  m.sensors[0] = m.sensors[1] = spec;
  m.sensor_present[setup.part] = true;
  m.sensor_present[1 - setup.part] = false;
  m.program.kind = dsp::ProgramKind::freeform;
  m.program.feed_mm_min = std::max(1.0, setup.feed_mm_min);
  m.program.repeats = 1;
  run.frames.resize(accel_g.values.size());
  const double full = std::ldexp(1.0, 31);
  for (std::size_t k = 0; k < accel_g.values.size(); ++k) {
    dsp::Frame& f = run.frames[k];
    f.sample_index = accel_g.grid_index[k] - accel_g.grid_index.front();
    for (int a = 0; a < 3; ++a) {
      const double c = std::round(accel_g.values[k][a] * kImportCountsPerG);
      if (c >= full - 1 || c <= -full) f.flags |= dsp::frame_flag::accel_saturated;
      f.accel_counts[3 * setup.part + a] = static_cast<std::int32_t>(std::clamp(c, -full, full - 1));
    }
    f.flags |= dsp::frame_flag::temp_missing;
    const double t_sp = clock.time_at(accel_g.grid_index[k]) - offset_s;
    if (!set_point.hold_outside && (t_sp < set_point.t_begin_s || t_sp > set_point.t_end_s)) {
      f.flags |= dsp::frame_flag::cmd_missing;
    } else {
      const Eigen::Vector3d p = set_point.position_mm(std::clamp(t_sp, set_point.t_begin_s, set_point.t_end_s));
      for (int a = 0; a < 3; ++a) f.cmd_mm[a] = p[a];
    }
  }
  run.frames.front().trigger = dsp::trigger::program_start;
  run.frames.back().trigger = dsp::trigger::program_end;
  return run;
}

std::string import_report_toml(const ImportReport& report) {
  auto str = [](const std::string& v) {
    std::string o = "\"";
    for (char c : v) o += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    return o + "\"";
  };
  auto clock = [&](const char* table, const UniformClock& c) {
    return std::string("\n[") + table + "]\nfs_hz = " + toml_number(c.fs_hz) + "\nt0_s = " + toml_number(c.t0_s) +
           "\nmedian_dt_s = " + toml_number(c.median_dt_s) + "\njitter_rms_s = " + toml_number(c.jitter_rms_s) +
           "\ngaps = " + std::to_string(c.gaps) + "\nlost_frames = " + std::to_string(c.lost_frames) + "\n";
  };
  std::string o =
      "# How this run was imported (eical import): the recorder's clock, the resampling\n"
      "# (cubic Lagrange onto the uniform clock, drivers/import/uniform_clock.hpp) and the\n"
      "# time offset recorder - set-point by cross-correlation with the structure's response\n"
      "# taken out (u: standard uncertainty, k = 1: block jackknife and the response beyond the\n"
      "# excited band, u_extension_s).\n";
  o += "format = \"eical-import/1\"\nkind = " + str(report.kind) + "\nsource = " + str(report.source) + "\n";
  if (!report.nc_source.empty()) o += "nc_source = " + str(report.nc_source) + "\n";
  o += "excitation = " + str(report.excitation) + "\nsamples = " + std::to_string(report.samples) + "\n";
  o += "# what the recorded acceleration was multiplied by (--accel-scale)\naccel_scale = " +
       toml_number(report.accel_scale) + "\n";
  o += clock("accel_clock", report.accel_clock);
  if (report.nc_clock) o += clock("nc_clock", *report.nc_clock);
  o += "\n[time_offset]\noffset_s = " + toml_number(report.offset.offset_s) +
       "\nu_s = " + toml_number(report.offset.u_s) + "\nu_extension_s = " + toml_number(report.offset.u_extension_s) +
       "\nstructure_peak = " + toml_number(report.offset.structure_peak) +
       "\nexplained = " + toml_number(report.offset.explained) +
       "\npeak_to_median = " + toml_number(report.offset.peak_to_median) +
       "\nblocks = " + std::to_string(report.offset.blocks) +
       "\nfine_step_s = " + toml_number(report.offset.fine_step_s) +
       "\n# measured (sensor axes) = gain · commanded (machine axes), at the offset\ngain = [";
  for (int i = 0; i < 3; ++i) {
    o += i ? ", [" : "[";
    for (int j = 0; j < 3; ++j) o += (j ? ", " : "") + toml_number(report.offset.gain(i, j));
    o += "]";
  }
  o += "]\n";
  if (report.mounting) {
    o += "\n# gravity (the capture's mean) and the commanded motion against the stated mounting\n[mounting]\n";
    o += "gravity_g = " + toml_number(report.mounting->gravity_g) +
         "\nstated_map = " + str(report.mounting->stated_map) +
         "\nconsistent = " + (report.mounting->consistent ? "true" : "false") + "\nfindings = [";
    for (std::size_t i = 0; i < report.mounting->findings.size(); ++i)
      o += (i ? ", " : "") + str(report.mounting->findings[i]);
    o += "]\n";
  }
  return o;
}

void write_import_report(const std::filesystem::path& run_dir, const ImportReport& report) {
  write_text_atomic(run_dir / "import.toml", import_report_toml(report));
}

void require_alignment(const OffsetEstimate& offset, const std::string& source) {
  if (offset.peak_to_median >= kMinPeakToMedian && offset.explained >= kMinExplained) return;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                ": the commanded acceleration is not found in the measured one (correlation peak %.1f x the median "
                "over all lags, %.0f needed; "
                "it explains %.2f %%, %.0f %% needed): wrong test parameters, axis or file, or a sensor on a part that "
                "does not move?",
                offset.peak_to_median, kMinPeakToMedian, 100.0 * offset.explained, 100.0 * kMinExplained);
  throw dsp::InputError(source + buf);
}

std::vector<std::string> axis_list(const std::string& letters, const std::string& what) {
  std::vector<std::string> out;
  for (char c : letters) {
    if (c < 'x' || c > 'z') throw dsp::InputError(what + ": '" + letters + "' is not a list of the letters x, y, z");
    const std::string a(1, c);
    if (std::find(out.begin(), out.end(), a) != out.end())
      throw dsp::InputError(what + ": '" + letters + "' names an axis twice");
    out.push_back(a);
  }
  return out;
}

}  // namespace eical::drivers
