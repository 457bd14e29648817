// eical simulate: a synthetic recorded run (eical-run/1 with truth.toml) from the simulator.
#include "drivers/config/scenario_file.hpp"
#include "dsp/core/error.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "sim/hidden/hidden_effects.hpp"
#include "sim/simulate.hpp"
#include "tools/commands.hpp"
#include "tools/sim_programs.hpp"

#include <cstdio>
#include <memory>

namespace eical::tools {

void register_simulate(CLI::App& app) {
  struct Opt {
    std::string program = "circle", direction = "ccw", plane = "xy", out, scenario, psd = "none";
    double arc_deg = 360.0, radius_mm = 10.0, feed_mm_min = 2500.0, noise_ug = 0.4, from_mm = 0.0, to_mm = 50.0;
    int repeats = 5, runs = 2;
    std::vector<double> targets{0.0, 10.0, 20.0, 30.0, 40.0};
    std::vector<std::string> hide;
    std::uint64_t seed = 1;
    bool gzip = false, overwrite = false, background = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("simulate", "Simulate a machine and its sensors; write a recorded run (eical-run/1)");
  std::string effects_help = "hide these effects (comma separated; run-format.md names) among tolerance-level deviations of sensors, machine, "
                             "PSD strips and KGM, at the sizes a faulty machine shows (sim/hidden/hidden_effects.cpp); with --program circle or step "
                             "(default: the program the first effect shows best in), --seed. Names:";
  for (const auto& e : sim::hideable_effects()) effects_help += " " + e;
  cmd->add_option("--hide", o->hide, effects_help)->delimiter(',')->check(CLI::IsMember(sim::hideable_effects()));
  cmd->add_flag("--background", o->background, "a baseline with the tolerance-level deviations only (no effect hidden)");
  auto* scenario = cmd->add_option("--scenario", o->scenario, "scenario file (eical-scenario/1, config/scenarios/README.md): machine errors, vibration, sensor truth, every effect")
                       ->check(CLI::ExistingFile);
  cmd->add_option("--program", o->program, "circle, step, positioning, rectangle, freeform or identify")
      ->default_val("circle")
      ->check(CLI::IsMember({"circle", "step", "positioning", "rectangle", "freeform", "identify"}))
      ->excludes(scenario);
  cmd->add_option("--psd", o->psd, "PSD strips: B (configuration B of the sample runs, for a circle of --radius), none; identify: B by default")
      ->default_val("none")
      ->check(CLI::IsMember({"B", "none"}));
  cmd->add_option("--plane", o->plane, "circle, rectangle: xy, zx or yz")->default_val("xy")->check(CLI::IsMember({"xy", "zx", "yz"}));
  cmd->add_option("--arc-deg", o->arc_deg, "circle: evaluated arc in deg (below 360: partial arc, up to 340)")->default_val(360.0)->check(CLI::Range(1.0, 360.0));
  cmd->add_option("--targets", o->targets, "positioning: targets on x, mm (comma separated)")->delimiter(',');
  cmd->add_option("--radius", o->radius_mm, "circle radius, mm")->default_val(10.0)->check(CLI::PositiveNumber);
  cmd->add_option("--feed", o->feed_mm_min, "feed, mm/min")->default_val(2500.0)->check(CLI::PositiveNumber);
  cmd->add_option("--repeats", o->repeats, "circle revolutions")->default_val(5)->check(CLI::Range(1, 1000));
  cmd->add_option("--direction", o->direction, "ccw, cw or both")->default_val("ccw")->check(CLI::IsMember({"ccw", "cw", "both"}));
  cmd->add_option("--from", o->from_mm, "step: start position on x, mm")->default_val(0.0);
  cmd->add_option("--to", o->to_mm, "step: end position on x, mm")->default_val(50.0);
  cmd->add_option("--runs", o->runs, "step: there-and-back pairs")->default_val(2)->check(CLI::Range(1, 1000));
  cmd->add_option("--noise", o->noise_ug, "sensor noise density, ug/sqrt(Hz) (two-sided)")->default_val(0.4)->check(CLI::NonNegativeNumber);
  cmd->add_option("--seed", o->seed, "random seed (same seed, same run)")->default_val(1);
  cmd->add_option("-o,--out", o->out, "run directory to write")->required();
  cmd->add_flag("--gzip", o->gzip, "write samples.csv.gz");
  cmd->add_flag("--overwrite", o->overwrite, "replace an existing run");
  auto* program_opt = cmd->get_option("--program");
  cmd->callback([o, program_opt] {
    const bool program_given = program_opt->count() > 0;
    sim::Scenario sc;
    if (!o->scenario.empty()) {
      sc = drivers::read_scenario_file(o->scenario);
    } else if (!o->hide.empty() || o->background) {
      const bool chosen = o->program == "circle" || o->program == "step";
      const std::string kind = o->hide.empty() ? (chosen ? o->program : "circle") : (program_given && chosen ? o->program : sim::program_for(o->hide));
      if (program_given && !chosen) throw dsp::InputError("simulate --hide/--background: --program must be circle or step");
      sc = sim::hidden_effect_scenario(o->hide, kind, o->seed);
    } else {
      sc = o->program == "circle"      ? sim::circle_scenario(o->radius_mm, o->feed_mm_min, o->repeats, o->direction, o->seed)
           : o->program == "step"      ? sim::step_scenario(o->from_mm, o->to_mm, o->feed_mm_min, o->runs, o->seed)
           : o->program == "rectangle" ? sim::rectangle_scenario(20.0, 10.0, o->feed_mm_min, o->plane, 1, o->seed)
           : o->program == "freeform"  ? freeform_scenario(o->feed_mm_min, o->seed)
           : o->program == "identify"  ? sim::identify_scenario(sim::psd_config_b(o->radius_mm), {"z"}, o->seed)
                                       : sim::positioning_scenario(o->targets, o->runs, o->feed_mm_min, o->seed);
      if (o->psd == "B") sc.meta.psd = sim::psd_config_b(o->radius_mm);
      if (o->program == "circle") {
        sc.meta.program.plane = o->plane;
        sc.meta.program.arc_deg = o->arc_deg;
      }
      for (auto& t : sc.truth) t.spec.noise_ug_per_rthz = o->noise_ug;
      for (auto& s : sc.meta.sensors) s.noise_ug_per_rthz = o->noise_ug;
    }
    const dsp::Run run = sim::simulate(sc);
    drivers::write_run(run, o->out, {.gzip = o->gzip, .overwrite = o->overwrite});
    std::printf("wrote %s: %zu samples, %.2f s, program %s\n", o->out.c_str(), run.frames.size(),
                static_cast<double>(run.frames.size()) / run.meta.acquisition.fs_hz, run.meta.program.kind.c_str());
  });
}

}  // namespace eical::tools
