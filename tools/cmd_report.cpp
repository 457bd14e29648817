// eical report RUN [--out DIR]: HTML report with SVG plots and CSV traces.
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/report/run_report.hpp"
#include "tools/run_files.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace eical::tools {

namespace {

// "calibration.toml, identified (psd) from run R; its covariance enters every U": the
// traceability of the sensor model. No per-sensor U is quoted: the identification sees
// head − table only, so one sensor's scale may trade off against the other's and its
// marginal U says nothing about the measurement's (eical analyze --budget gives that share).
std::string calibration_text(const std::string& file, const drivers::SensorCalibration& cal) {
  const std::string t = file + ", identified (" + cal.method + ") from run " + (cal.run_id.empty() ? "?" : cal.run_id);
  if (!cal.covariance) return t + "; the file holds no covariance: U from the data sheet's tolerances";
  return t +
         "; its covariance enters every U of this report (its share: eical analyze --budget, sensor scale and "
         "mounting)";
}

}  // namespace

void register_report(CLI::App& app) {
  struct Opt {
    std::string run, out, calibration, tolerances, operator_name, serial;
    bool force = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("report", "Render the HTML report of a recorded run");
  cmd->add_option("run", o->run, "run directory (eical-run/1)")->required();
  cmd->add_option("-o,--out", o->out, "report folder (default: RUN/report)");
  cmd->add_option("--calibration", o->calibration,
                  "sensor calibration (eical-sensor-cal/1) instead of the run's data sheet")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tolerances", o->tolerances,
                  "tolerance file (eical-tolerances/1): pass/fail of G, F (ISO 230-4) and A, B, R, E, M (ISO 230-2), "
                  "header fields")
      ->check(CLI::ExistingFile);
  cmd->add_option("--operator", o->operator_name, "operator's name for the header");
  cmd->add_option("--serial", o->serial, "the machine's serial number for the header");
  cmd->add_flag("--force", o->force, "replace a report already in the folder");
  cmd->callback([o] {
    const std::filesystem::path dir =
        o->out.empty() ? std::filesystem::path(o->run) / "report" : std::filesystem::path(o->out);
    // A report may be signed already: replacing it takes a word, not a default.
    if (std::filesystem::exists(dir / "report.html") && !o->force)
      throw dsp::InputError("report: " + dir.string() + " holds a report already (--force to replace it)");
    dsp::Run run = drivers::read_run(o->run);
    dsp::AnalysisOptions opt;
    report::ReportOptions ro;
    if (!o->calibration.empty()) {
      const drivers::SensorCalibration cal = drivers::read_sensor_calibration(o->calibration, run.meta);
      drivers::apply_calibration(cal, run.meta, opt);
      ro.calibration = calibration_text(o->calibration, cal);
    }
    if (!o->tolerances.empty()) ro.tolerances = report::read_tolerances(o->tolerances);
    ro.operator_name = o->operator_name, ro.serial = o->serial;
    const dsp::Analysis a = dsp::analyze_run(run, opt);
    const auto file = report::write_run_report(run, a, dir, ro);
    write_file_atomic(dir / "result.json", drivers::result_json(run, a).dump(2) + "\n");
    std::printf("report: %s\n", file.c_str());
  });
}

}  // namespace eical::tools
