// eical demo: the main job. A calibration as a machine builder runs one, on a simulated
// machine (tools/demo/demo_stages.hpp):
//   1. the sensors identified on site (gen-nc identify's program over the PSD strips);
//   2. the circular test R10 F2500, both directions (or --radius --feed --repeats --psd),
//      through the daemon's code path;
//   3. its analysis with that calibration: verdict, G ± U, U against the noise bound, the
//      error against the simulator's truth, result.json and the report;
//   4. a test beyond the instrument (R150 F4000 without strips): not measurable, and why.
// Exit status 0 when part one's verdict is ok, else that verdict's (tools/exit_codes.hpp).
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/figures_on_path.hpp"
#include "tools/commands.hpp"
#include "tools/demo/demo_stages.hpp"
#include "tools/exit_codes.hpp"
#include "tools/plan/psd_layouts.hpp"
#include "tools/report/run_report.hpp"
#include "tools/run_files.hpp"

#include <chrono>
#include <cstdio>
#include <memory>

namespace eical::tools {
namespace {

// Part one's circle: its radius, feed, revolutions and strips (demo::DemoTest).
void add_design_options(CLI::App* cmd, demo::DemoTest& test, std::string& psd) {
  cmd->add_option("--radius", test.radius_mm, "part 1's circle: radius, mm")
      ->default_val(10.0)
      ->check(CLI::Range(1.0, 500.0));
  cmd->add_option("--feed", test.feed_mm_min, "part 1's circle: feed, mm/min")
      ->default_val(2500.0)
      ->check(CLI::Range(100.0, 20000.0));
  cmd->add_option("--repeats", test.repeats, "part 1's circle: revolutions per direction")
      ->default_val(5)
      ->check(CLI::Range(1, 20));
  cmd->add_option("--psd", psd,
                  "part 1's PSD strips about the circle: B (2), B4, B8, B16 along its path, R4, R8, R16 turned "
                  "radial")
      ->default_val("B")
      ->check(CLI::IsMember(plan::psd_layout_names()));
}

}  // namespace

void register_demo(CLI::App& app) {
  struct Opt {
    std::string out = "out/demo";
    std::uint64_t seed = 1;
    bool realtime = false;
    demo::DemoTest test;
    std::string psd = "B";
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand(
      "demo",
      "Main job: identify the sensors on site, run a circular test (R10 F2500 unless told) with PSD strips end to end, "
      "then show a test beyond the instrument");
  cmd->add_option("-o,--out", o->out, "output folder (the runs, the calibration, result.json, the report)")
      ->default_val("out/demo");
  cmd->add_option("--seed", o->seed, "simulation seed: the machine, its sensors and strips")->default_val(1);
  cmd->add_flag("--realtime", o->realtime, "pace the simulated DAQ at 10 kHz (as eicald does) instead of free-running");
  add_design_options(cmd, o->test, o->psd);
  cmd->footer("Exit status: 0 when the calibration's verdict is ok, 2 degraded, 3 not measurable, 1 an error.");
  cmd->callback([o] {
    namespace fs = std::filesystem;
    const auto t0 = std::chrono::steady_clock::now();
    const fs::path out = o->out;
    fs::create_directories(out);

    const plan::PsdLayout layout = plan::psd_layout(o->psd);
    if (layout.strips == 0) throw CLI::ValidationError("--psd", "the demo's circle runs over strips, not none");
    o->test.strips = layout.strips, o->test.facing = layout.facing;
    const demo::DemoMachine machine = demo::demo_machine(o->seed, o->test);
    std::printf("eical demo, part 1: a calibration, as on the machine (simulated, seed %llu)\n",
                static_cast<unsigned long long>(o->seed));
    std::printf("  the test: %s\n", plan::describe(machine.program).c_str());

    const demo::OnSiteIdentification id = demo::identify_on_site(machine, out);
    std::printf("  1. sensors identified on site from %s in %.1f s: %s\n", id.run_dir.c_str(), id.seconds,
                id.file.c_str());

    demo::RecordedTest test = demo::record_through_daemon_path(machine.circle, o->realtime);
    drivers::write_run(test.run, out / "run", {.gzip = false, .overwrite = true});
    std::printf(
        "  2. the circular test recorded through the daemon's path in %.1f s: frames %llu, through the ring "
        "%llu, overruns %llu, lost %llu\n",
        test.seconds, static_cast<unsigned long long>(test.stats.frames_read),
        static_cast<unsigned long long>(test.stats.frames_consumed),
        static_cast<unsigned long long>(test.stats.overruns), static_cast<unsigned long long>(test.frames_lost));

    const auto t_an = std::chrono::steady_clock::now();
    const dsp::Analysis a = demo::analyze_with(test.run, id.calibration);
    const auto truth = dsp::figures_on_path(test.run, test.truth_mm, a);
    write_file_atomic(out / "result.json", drivers::result_json(test.run, a).dump(2) + "\n");
    const auto report = report::write_run_report(test.run, a, out / "report");
    std::printf("  3. analysed with the calibration in %.1f s:\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t_an).count());
    std::fputs(demo::headline_text(a, truth).c_str(), stdout);
    std::fputs(summary_text(test.run, a).c_str(), stdout);
    std::printf("  written: %s/run, %s, %s/result.json, %s\n", out.c_str(), id.file.c_str(), out.c_str(),
                report.c_str());

    std::printf(
        "\neical demo, part 2: a test beyond the instrument (R150 F4000, one revolution, no PSD strips, "
        "data-sheet sensors)\n");
    const dsp::Analysis beyond = demo::beyond_the_instrument(o->seed);
    std::fputs(demo::headline_text(beyond, {}).c_str(), stdout);
    for (const auto& r : beyond.verdict_reasons) std::printf("    - %s\n", r.c_str());
    std::printf("  (eical plan --program circle --radius 150 names the nearest test that is measurable)\n");

    std::printf("\n  runtime %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::fflush(stdout);
    if (const int code = verdict_exit_code(a.verdict); code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace eical::tools
