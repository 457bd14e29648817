#include "tools/cmd_simulate_export.hpp"

#include "drivers/import/capture_export.hpp"
#include "drivers/import/shaketune_file.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/simulate.hpp"

#include <cstdio>
#include <utility>

namespace eical::tools {
namespace {

std::string num(double v) { return drivers::toml_number(v); }

// Runs of lost frames (a gap each).
std::size_t gaps_of(const sim::CaptureSamples& s) {
  std::size_t gaps = 0;
  for (std::size_t n = 0; n < s.kept.size(); ++n)
    if (!s.kept[n] && (n == 0 || s.kept[n - 1])) ++gaps;
  return gaps;
}

// Each format and the name --export takes and truth.toml records (as ProgramKind's names).
constexpr std::pair<ExportFormat, const char*> kFormatNames[] = {
    {ExportFormat::klipper, "klipper"}, {ExportFormat::shaketune, "shaketune"}, {ExportFormat::csv, "csv"}};

}  // namespace

const char* export_format_name(ExportFormat format) {
  for (const auto& [f, name] : kFormatNames)
    if (f == format) return name;
  return "?";
}

ExportFormat parse_export_format(const std::string& name) {
  std::string names;
  for (const auto& [f, text] : kFormatNames) {
    if (name == text) return f;
    names += std::string(names.empty() ? "" : ", ") + text;
  }
  throw dsp::InputError("simulate --export: '" + name + "' is not one of " + names);
}

std::string simulate_with_export(const sim::Scenario& scenario, const ExportRequest& request, const std::string& out,
                                 bool gzip, bool overwrite) {
  const auto set_point = sim::scenario_set_point(scenario);
  sim::check_budget(scenario, *set_point);  // before the capture's per-frame buffers
  const double fs = scenario.meta.acquisition.fs_hz;
  const auto n_frames = static_cast<std::size_t>(std::ceil(set_point->duration_s() * fs)) + 1;
  const sim::CaptureSamples samples = sim::capture_samples(request.clock, n_frames, fs);
  sim::JitteredCapture jittered{samples.jitter_s, {}};
  dsp::Run run = sim::simulate(scenario, *set_point, nullptr, &jittered);
  const int part = run.meta.sensor_present[1] ? 1 : 0;

  std::string files,
      truth =
          "\n[export]\n# The run as another system recorded it (eical simulate --export): frame n taken at\n"
          "# n/fs + jitter, stamped offset_s + that time; lost batches left out. offset_s is what\n"
          "# eical import must find: recorder time - set-point time.\n";
  truth += "format = \"" + std::string(export_format_name(request.format)) + "\"\nsensor = \"" +
           std::string(part ? "head" : "table") + "\"\n";
  const drivers::StampedAccel capture =
      drivers::exported_capture(run, jittered, samples, request.clock, part, request.target);
  const bool klipper_samples = request.format != ExportFormat::csv;
  if (klipper_samples) {
    if (request.format == ExportFormat::klipper)
      drivers::write_klipper_capture(request.target, capture);
    else  // one measurement, named as Shake&Tune names its axis tests
      drivers::write_shaketune_stdata(request.target, {{"axis_" + run.meta.id, capture}});
    files = request.target;
    truth += "file = \"" + request.target + "\"\noffset_s = " + num(request.clock.offset_s) + "\n";
  } else {
    const std::string accel_file = request.target + "-accel.csv";
    const std::string nc_file = request.target + (request.nc_format == "halsampler" ? "-nc.txt" : "-nc.csv");
    drivers::write_accel_csv(accel_file, capture, drivers::AccelUnit::mps2);
    const drivers::NcTrace trace =
        drivers::exported_nc_trace(*set_point, request.servo_period_s, request.nc_offset_s, nc_file);
    if (request.nc_format == "halsampler")
      drivers::write_halsampler(nc_file, trace, std::llround(trace.t_s.front() / request.servo_period_s));
    else
      drivers::write_nc_csv(nc_file, trace);
    files = accel_file + " and " + nc_file;
    truth += "file = \"" + accel_file + "\"\nnc_file = \"" + nc_file + "\"\nnc_format = \"" + request.nc_format +
             "\"\nservo_period_s = " + num(request.servo_period_s) + "\nnc_offset_s = " + num(request.nc_offset_s) +
             "\ncapture_offset_s = " + num(request.clock.offset_s) +
             "\noffset_s = " + num(request.clock.offset_s - request.nc_offset_s) + "\n";
  }
  truth += "jitter_rms_s = " + num(samples.jitter_rms_s) + "\nbatch = " + std::to_string(request.clock.batch) +
           "\nlost_frames = " + std::to_string(samples.lost) + "\ngaps = " + std::to_string(gaps_of(samples)) + "\n";
  if (run.truth_toml) *run.truth_toml += truth;
  drivers::write_run(run, out, {.gzip = gzip, .overwrite = overwrite});
  char line[512];
  std::snprintf(line, sizeof line, "exported %s: %zu samples (%zu lost in %zu gaps), jitter %.1f us rms, offset %.6f s",
                files.c_str(), capture.t_s.size(), samples.lost, gaps_of(samples), samples.jitter_rms_s * 1e6,
                klipper_samples ? request.clock.offset_s : request.clock.offset_s - request.nc_offset_s);
  return line;
}

}  // namespace eical::tools
