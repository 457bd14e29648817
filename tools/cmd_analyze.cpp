// eical analyze RUN [--json]: the pipeline and the program's evaluation on a recorded run.
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/exec/thread_for.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/file_spill.hpp"
#include "drivers/run_io/run_stream.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/verdict.hpp"
#include "tools/commands.hpp"
#include "tools/exit_codes.hpp"
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/report/tolerances.hpp"
#include "tools/run_files.hpp"

#include <malloc.h>
#include <cstdio>
#include <memory>

namespace eical::tools {

void register_analyze(CLI::App& app) {
  struct Opt {
    std::string run, dynamic = "two-stage", calibration, tolerances;
    bool json = false, no_zupt = false, coriolis = false;
    int draws = 100;
    bool no_suggest = false, budget = false;
    std::string nbs = "auto";
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand(
      "analyze", "Evaluate a recorded run: every program's figures with their uncertainty U (k = 2) and the verdict");
  cmd->add_option("run", o->run, "run directory (eical-run/1)")->required();
  cmd->add_flag("--json", o->json, "print the eical-result/1 document");
  cmd->add_option("--dynamic", o->dynamic, "dynamic compensation: two-stage or none")
      ->default_val("two-stage")
      ->check(CLI::IsMember({"two-stage", "none"}));
  cmd->add_flag("--no-zupt", o->no_zupt, "skip the zero-velocity update after the motion");
  cmd->add_option("--nbs", o->nbs, "hold axes whose set-point does not move (Bild 7-8): auto (rectangles), on, off")
      ->default_val("auto")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_flag("--coriolis", o->coriolis,
                "correct the Earth-rate Coriolis acceleration (3-6) with [site] latitude and heading");
  cmd->add_option("--calibration", o->calibration,
                  "sensor calibration (eical-sensor-cal/1, from eical identify) instead of the run's data sheet")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tolerances", o->tolerances,
                  "tolerance file (eical-tolerances/1, as eical report takes): each figure and the run decided by "
                  "ISO 14253-1 with U (k = 2)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--budget", o->budget,
                "each source of the error alone (integration noise, sensor scale, timing, temperature, strip offsets "
                "and nonlinearity): its U of every figure, in the text and the JSON (40 draws a source: seconds)");
  cmd->add_option("--draws", o->draws, "Monte Carlo draws of the uncertainty (seeded, deterministic)")
      ->default_val(100)
      ->check(CLI::Range(10, 100000));
  cmd->add_flag(
      "--no-suggest", o->no_suggest,
      "do not look for a measurable variant when the test is not measurable (it simulates variants: seconds)");
  cmd->footer(
      "Exit status: 0 verdict ok, 2 degraded, 3 not measurable, 1 an error; with --tolerances and the verdict ok: 0 "
      "conformance proven, 4 non-conformance proven, 5 undecided (docs/command-line.md, \"Exit status\").");
  cmd->callback([o] {
    // Buffers above 256 kB are mapped and go back to the system when freed: the streamed
    // analysis' passes (the first pass' records, a revolution, the repeats' sums) then do not
    // stack in the heap (glibc's adaptive threshold kept them: 156 -> 143 MB peak, 10 min).
    mallopt(M_MMAP_THRESHOLD, 256 * 1024);
    // Read as it streams: memory bounded whatever the run's length (dsp/stream).
    drivers::RunStream stream(o->run);
    dsp::Run& run = stream.header();
    // Read before the analysis: a bad tolerance file fails in a second, not after it.
    std::optional<report::Tolerances> tol;
    if (!o->tolerances.empty()) tol = report::read_tolerances(o->tolerances);
    dsp::AnalysisOptions opt;
    if (!o->calibration.empty())
      drivers::apply_calibration(drivers::read_sensor_calibration(o->calibration, run.meta), run.meta, opt);
    opt.dynamic = o->dynamic == "none" ? dsp::DynamicComp::none : dsp::DynamicComp::two_stage;
    opt.zupt = !o->no_zupt;
    if (o->nbs != "auto") opt.nbs = o->nbs == "on";
    opt.coriolis = o->coriolis;
    opt.uncertainty.draws = o->draws;
    opt.uncertainty.budget = o->budget;
    opt.parallel = drivers::thread_for();
    dsp::StreamOptions so;
    so.spills = drivers::file_spills(drivers::default_spill_dir());
    so.spill_trace = so.spill_corrections = true;  // a CSV reads slower than a spill, a spill faster than the smoother
    dsp::Analysis a = drivers::analyze_stream(stream, opt, so);
    if (tol) {
      a.conformance = dsp::decide_conformance(a, report::figure_tolerances(*tol));
      dsp::judge(run.meta.program, a);  // the tolerance, not the fixed limit, says what U must resolve
    }
    if (a.verdict == dsp::Verdict::not_measurable && !o->no_suggest) plan::suggest_measurable_test(run, a);
    if (o->json)
      std::printf("%s\n", drivers::result_json(run, a).dump(2).c_str());
    else
      std::fputs(summary_text(run, a).c_str(), stdout);
    std::fflush(stdout);
    const std::optional<dsp::Conformance> decision =
        a.conformance ? std::optional(a.conformance->overall) : std::nullopt;
    if (const int code = result_exit_code(a.verdict, decision); code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace eical::tools
