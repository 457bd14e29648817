// eical demo: the main job. A simulated calibration end to end through the code path of
// the daemon: simulated machine and sensors (sim backend) → acquisition thread → SPSC
// ring → DSP thread with the measurement session (M101 tare and start, M102 segments,
// M103 stop) and the live pipeline → the recording written as an eical-run/1 directory →
// the same analysis eicald runs → result.json and an HTML report.
#include "drivers/acquisition/pump.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/source/sim_source.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"
#include "tools/commands.hpp"
#include "tools/report/run_report.hpp"
#include "tools/run_files.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace eical::tools {

void register_demo(CLI::App& app) {
  struct Opt {
    std::string out = "out/demo";
    std::uint64_t seed = 1;
    bool realtime = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("demo", "Main job: a simulated circular test (R10, F2500, 5 repeats) end to end");
  cmd->add_option("-o,--out", o->out, "output folder (the run, result.json, report)")->default_val("out/demo");
  cmd->add_option("--seed", o->seed, "simulation seed")->default_val(1);
  cmd->add_flag("--realtime", o->realtime, "pace the simulated DAQ at 10 kHz (as eicald does) instead of free-running");
  cmd->callback([o] {
    namespace fs = std::filesystem;
    const auto t0 = std::chrono::steady_clock::now();
    // The test case: R = 10 mm, F = 2500 mm/min, 5 repeats, noise 0.4 µg/√Hz, 10 kHz.
    sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 5, "ccw", o->seed);
    drivers::SimSource source(sc, {.pacing = o->realtime ? drivers::Pacing::realtime : drivers::Pacing::free_running});
    source.open();
    const dsp::RunMeta& meta = source.meta();

    drivers::FrameRing ring(1 << 16);
    dsp::SessionConfig scfg;
    scfg.fs_hz = meta.acquisition.fs_hz;
    scfg.max_measurement_s = 60.0;
    dsp::MeasurementSession session(scfg);
    dsp::Pipeline live(dsp::pipeline_config(meta, static_cast<std::size_t>(scfg.max_measurement_s * scfg.fs_hz)));
    std::atomic<bool> stop{false};
    const auto stats = drivers::pump(
        source, ring,
        [&](const dsp::Frame& f) {
          session.on_frame(f);
          if (session.state().state() == dsp::State::measuring || f.trigger == dsp::trigger::program_end) live.step(f);
        },
        stop);
    if (!stats.source_error.empty()) throw std::runtime_error(stats.source_error);
    const auto t_acq = std::chrono::steady_clock::now();

    std::vector<dsp::Frame> frames;
    frames.reserve(session.recorder_capacity());
    if (!session.take(frames))
      throw std::runtime_error("the simulated program did not complete a measurement (M101..M103); state " +
                               std::string(dsp::to_string(session.state().state())));
    dsp::Run run;
    run.meta = meta;
    run.meta.created = "";
    run.channels = source.program_run()->channels;
    run.truth_toml = source.program_run()->truth_toml;
    run.frames = std::move(frames);

    const fs::path out = o->out;
    fs::create_directories(out);
    drivers::write_run(run, out / "run", {.gzip = false, .overwrite = true});
    const dsp::Analysis a = dsp::analyze_run(run);
    session.evaluation_done();
    write_file_atomic(out / "result.json", drivers::result_json(run, a).dump(2) + "\n");
    const auto report = report::write_run_report(run, a, out / "report");
    const auto t1 = std::chrono::steady_clock::now();

    const double runtime_s = std::chrono::duration<double>(t1 - t0).count();
    std::printf("eical demo: simulated circular test R10 F2500 x5 (ccw), both sensors, 0.4 ug/sqrt(Hz), 10 kHz\n");
    std::printf("  frames acquired %llu, through the ring %llu, overruns %llu, lost %llu\n",
                static_cast<unsigned long long>(stats.frames_read),
                static_cast<unsigned long long>(stats.frames_consumed), static_cast<unsigned long long>(stats.overruns),
                static_cast<unsigned long long>(session.counters().frames_lost));
    std::fputs(summary_text(run, a).c_str(), stdout);
    std::printf("  live (causal) estimate at M103, before ZUPT: x %.4f mm, y %.4f mm\n", live.live().pos_mm.x(),
                live.live().pos_mm.y());
    std::printf("  runtime %.2f s (acquisition and DSP %.2f s)\n", runtime_s,
                std::chrono::duration<double>(t_acq - t0).count());
    std::printf("  written: %s/run (recorded run), %s/result.json, %s\n", out.c_str(), out.c_str(), report.c_str());
  });
}

}  // namespace eical::tools
