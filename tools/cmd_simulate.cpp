// eical simulate: a synthetic recorded run (eical-run/1 with truth.toml) from the simulator.
#include "drivers/config/scenario_file.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/gcode/dialect_id.hpp"
#include "sim/hidden/hidden_effects.hpp"
#include "sim/regimes/klipper_like.hpp"
#include "sim/regimes/regimes.hpp"
#include "sim/simulate.hpp"
#include "tools/cmd_simulate_export.hpp"
#include "tools/commands.hpp"
#include "tools/envelope_options.hpp"
#include "tools/plan/psd_layouts.hpp"
#include "tools/sim_programs.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>

namespace eical::tools {
namespace {

// What `eical simulate` is told (its options, add_*_options below).
struct SimulateOptions {
  std::string program = "circle", direction = "ccw", plane = "xy", out, scenario, psd = "none";
  double arc_deg = 360.0, radius_mm = 10.0, feed_mm_min = 2500.0, noise_ug = 0.4, from_mm = 0.0, to_mm = 50.0;
  int repeats = 5, runs = 2;
  std::vector<double> targets{0.0, 10.0, 20.0, 30.0, 40.0};
  std::vector<std::string> hide;
  std::uint64_t seed = 1;
  bool gzip = false, overwrite = false, background = false;
  // Regimes of runs measured by other systems.
  std::string regime, sensors, mems, wrong_mounting, sweep_axis = "x";
  std::string dialect = "linuxcnc";  // of the scenario's [program] gcode_file
  double fs_hz = 0.0;
  std::vector<std::string> resonance;
  bool klipper_legacy = false;
  double freq_start = 0.0, freq_end = 0.0, hz_per_sec = 0.0, accel_per_hz = 0.0, sweeping_accel = -1.0,
         sweeping_period = -1.0;
  // Export.
  std::vector<std::string> export_to;
  std::string export_nc = "halsampler";
  double export_offset_s = 100.0, export_jitter_us = -1.0, export_nc_offset_s = 1234.5678;
  int export_lost_batches = 2, export_batch = 16;
  // The machine and the simulator's budget.
  EnvelopeOptions envelope;
  double max_duration_s = sim::kMaxSimulatedS;
};

// "FREQ,ZETA,GAIN,AXIS" (AXIS: x, y, z or dx,dy[,dz]).
sim::StructuralMode parse_mode(const std::string& text) {
  std::stringstream ss(text);
  std::string f, z, g;
  if (!std::getline(ss, f, ',') || !std::getline(ss, z, ',') || !std::getline(ss, g, ','))
    throw dsp::InputError("--resonance '" + text + "': expected FREQ_HZ,DAMPING_RATIO,GAIN,AXIS");
  std::string axis;
  std::getline(ss, axis);
  sim::StructuralMode m;
  try {
    m.frequency_hz = std::stod(f), m.damping_ratio = std::stod(z), m.gain = std::stod(g);
  } catch (const std::exception&) {
    throw dsp::InputError("--resonance '" + text + "': frequency, damping ratio and gain must be numbers");
  }
  if (!(m.frequency_hz > 0.0) || !(m.damping_ratio > 0.0 && m.damping_ratio < 1.0))
    throw dsp::InputError("--resonance '" + text + "': the frequency must be positive and the damping ratio in (0, 1)");
  m.direction = sim::nc::test_direction(axis.empty() ? "x" : axis, "--resonance axis");
  return m;
}

sim::nc::KlipperTest sweep_test(const SimulateOptions& o) {
  sim::nc::KlipperTest k = o.klipper_legacy ? sim::nc::KlipperTest::legacy() : sim::nc::KlipperTest::current();
  if (o.freq_start > 0.0) k.freq_start_hz = o.freq_start;
  if (o.freq_end > 0.0) k.freq_end_hz = o.freq_end;
  if (o.hz_per_sec > 0.0) k.hz_per_sec = o.hz_per_sec;
  if (o.accel_per_hz > 0.0) k.accel_per_hz = o.accel_per_hz;
  if (o.sweeping_accel >= 0.0) k.sweeping_accel_mm_s2 = o.sweeping_accel;
  if (o.sweeping_period >= 0.0) k.sweeping_period_s = o.sweeping_period;
  return k;
}

// The identification's strips: --psd's about the circle, configuration B for none.
std::vector<dsp::PsdSpec> identify_strips(const SimulateOptions& o) {
  const plan::PsdLayout layout = plan::psd_layout(o.psd);
  return layout.strips == 0 ? sim::psd_config_b(o.radius_mm) : sim::psd_ring(o.radius_mm, layout.strips, layout.facing);
}

// What --program takes: every program kind, and Klipper's resonance sweep (a scenario, not a
// program a run carries).
std::vector<std::string> simulate_programs() {
  std::vector<std::string> names;
  for (const auto& [kind, name] : dsp::kProgramKindNames) names.emplace_back(name);
  names.emplace_back("sweep");
  return names;
}

// The scenario of --program with its options; "sweep" is Klipper's resonance test, not a
// calibration program (no ProgramKind of its own).
sim::Scenario program_scenario(const SimulateOptions& o) {
  const std::optional<dsp::ProgramKind> kind = dsp::parse_program_kind(o.program);
  if (!kind) return sim::sweep_scenario(sweep_test(o), sim::nc::test_direction(o.sweep_axis, "--sweep-axis"), o.seed);
  switch (*kind) {
    case dsp::ProgramKind::circle:
      return sim::circle_scenario(o.radius_mm, o.feed_mm_min, o.repeats, o.direction, o.seed);
    case dsp::ProgramKind::step: return sim::step_scenario(o.from_mm, o.to_mm, o.feed_mm_min, o.runs, o.seed);
    case dsp::ProgramKind::rectangle: return sim::rectangle_scenario(20.0, 10.0, o.feed_mm_min, o.plane, 1, o.seed);
    case dsp::ProgramKind::freeform: return freeform_scenario(o.feed_mm_min, o.seed);
    case dsp::ProgramKind::identify: return sim::identify_scenario(identify_strips(o), {"z"}, o.seed);
    case dsp::ProgramKind::positioning: break;
  }
  return sim::positioning_scenario(o.targets, o.runs, o.feed_mm_min, o.seed);
}

sim::Scenario base_scenario(const SimulateOptions& o, bool program_given) {
  if (!o.regime.empty()) {
    if (!o.scenario.empty() || program_given)
      throw dsp::InputError("simulate --regime: the regime sets the program (no --scenario or --program)");
    return sim::klipper_like_scenario(o.background
                                          ? std::vector<std::string>{}
                                          : (o.hide.empty() ? std::vector<std::string>{"machine.resonance"} : o.hide),
                                      o.seed);
  }
  if (!o.scenario.empty()) return drivers::read_scenario_file(o.scenario, sim::gcode::dialect_from_name(o.dialect));
  if (!o.hide.empty() || o.background) {
    const std::optional<dsp::ProgramKind> asked = dsp::parse_program_kind(o.program);
    const bool chosen = asked == dsp::ProgramKind::circle || asked == dsp::ProgramKind::step;
    const dsp::ProgramKind kind = o.hide.empty() ? (chosen ? *asked : dsp::ProgramKind::circle)
                                                 : (program_given && chosen ? *asked : sim::program_for(o.hide));
    if (program_given && !chosen)
      throw dsp::InputError("simulate --hide/--background: --program must be circle or step");
    return sim::hidden_effect_scenario(o.hide, kind, o.seed);
  }
  sim::Scenario sc = program_scenario(o);
  if (const auto layout = plan::psd_layout(o.psd); layout.strips > 0)
    sc.meta.psd = sim::psd_ring(o.radius_mm, layout.strips, layout.facing);
  if (sc.meta.program.kind == dsp::ProgramKind::circle && !sc.sweep.on) {
    sc.meta.program.plane = o.plane;
    sc.meta.program.arc_deg = o.arc_deg;
  }
  for (auto& t : sc.truth) t.spec.noise_ug_per_rthz = o.noise_ug;
  for (auto& s : sc.meta.sensors) s.noise_ug_per_rthz = o.noise_ug;
  return sc;
}

// The regime flags on top of the scenario: chip and rate first (they set the data sheet),
// then which sensors, the mounting and the modes.
void apply_regime_flags(const SimulateOptions& o, sim::Scenario& sc) {
  const bool fixed = !o.regime.empty();
  if (fixed &&
      (!o.mems.empty() || o.fs_hz > 0.0 || !o.sensors.empty() || !o.wrong_mounting.empty() || !o.resonance.empty()))
    throw dsp::InputError("simulate --regime: the regime draws chip, rate, sensors, mounting and modes itself");
  if (!o.mems.empty()) {
    if (!o.scenario.empty() || !o.hide.empty() || o.background)
      throw dsp::InputError(
          "simulate --mems: not with --scenario/--hide/--background (a scenario's [mems] table does it there)");
    sim::apply_mems(sc, sim::mems_chip(o.mems), o.fs_hz);
  } else if (o.fs_hz > 0.0) {
    sim::set_daq_rate(sc, o.fs_hz);
  }
  if (!o.sensors.empty()) sim::set_sensors_present(sc, o.sensors);
  if (!o.wrong_mounting.empty()) {
    sim::apply_wrong_mounting(sc, sc.meta.sensor_present[1] ? 1 : 0, o.wrong_mounting);
    if (!sc.effects_present.empty() || !sc.effects_background.empty())
      sc.effects_present.push_back("sensor.misalignment");
  }
  if (!o.resonance.empty()) {
    for (const auto& r : o.resonance) sc.resonance.modes.push_back(parse_mode(r));
    sc.resonance.part = sc.meta.sensor_present[1] ? 1 : 0;
    if (!sc.effects_present.empty() || !sc.effects_background.empty())
      sc.effects_present.push_back("machine.resonance");
  }
}

// --hide, --background, --scenario and the program with its sizes.
void add_program_options(CLI::App& cmd, SimulateOptions& o) {
  std::string effects_help =
      "hide these effects (comma separated; run-format.md names) among tolerance-level deviations of sensors, machine, "
      "PSD strips and KGM, at the sizes a faulty machine shows (sim/hidden/hidden_effects.cpp); with --program circle "
      "or step "
      "(default: the program the first effect shows best in), --seed; with --regime klipper-like: machine.resonance, "
      "sensor.misalignment. Names:";
  for (const auto& e : sim::hideable_effects()) effects_help += " " + e;
  cmd.add_option("--hide", o.hide, effects_help)->delimiter(',')->check(CLI::IsMember(sim::hideable_effects()));
  cmd.add_flag("--background", o.background, "a baseline with the tolerance-level deviations only (no effect hidden)");
  auto* scenario = cmd.add_option("--scenario", o.scenario,
                                  "scenario file (eical-scenario/1, config/scenarios/README.md): machine errors, "
                                  "vibration, sensor truth, every effect")
                       ->check(CLI::ExistingFile);
  cmd.add_option("--dialect", o.dialect,
                 "the control the scenario's [program] gcode_file is written for: linuxcnc, fanuc, sinumerik or "
                 "heidenhain-iso (dwell units, inch/metric codes, comments and block syntax; as gen-nc --dialect)")
      ->default_val("linuxcnc")
      ->check(CLI::IsMember({"linuxcnc", "fanuc", "sinumerik", "heidenhain-iso"}))
      ->needs(scenario);
  cmd.add_option(
         "--program", o.program,
         "circle, step, positioning, rectangle, freeform, identify or sweep (Klipper's resonance test, no standstill)")
      ->default_val("circle")
      ->check(CLI::IsMember(simulate_programs()))
      ->excludes(scenario);
  cmd.add_option("--psd", o.psd,
                 "PSD strips about a circle of --radius: B (configuration B of the sample runs: 2 strips), B4, B8, B16 "
                 "(that many, evenly around it, along its path), R4, R8, R16 (the same, turned radial), none; "
                 "identify: B by default")
      ->default_val("none")
      ->check(CLI::IsMember(plan::psd_layout_names()));
  cmd.add_option("--plane", o.plane, "circle, rectangle: xy, zx or yz")
      ->default_val("xy")
      ->check(CLI::IsMember({"xy", "zx", "yz"}));
  cmd.add_option("--arc-deg", o.arc_deg, "circle: evaluated arc in deg (below 360: partial arc, up to 340)")
      ->default_val(360.0)
      ->check(CLI::Range(1.0, 360.0));
  cmd.add_option("--targets", o.targets, "positioning: targets on x, mm (comma separated)")->delimiter(',');
  cmd.add_option("--radius", o.radius_mm, "circle radius, mm")->default_val(10.0)->check(CLI::PositiveNumber);
  cmd.add_option("--feed", o.feed_mm_min, "feed, mm/min")->default_val(2500.0)->check(CLI::PositiveNumber);
  cmd.add_option("--repeats", o.repeats, "circle revolutions")->default_val(5)->check(CLI::Range(1, 1000));
  cmd.add_option("--direction", o.direction, "ccw, cw or both")
      ->default_val("ccw")
      ->check(CLI::IsMember({"ccw", "cw", "both"}));
  cmd.add_option("--from", o.from_mm, "step: start position on x, mm")->default_val(0.0);
  cmd.add_option("--to", o.to_mm, "step: end position on x, mm")->default_val(50.0);
  cmd.add_option("--runs", o.runs, "step: there-and-back pairs")->default_val(2)->check(CLI::Range(1, 1000));
}

// The noise, the seed and where the run goes.
void add_output_options(CLI::App& cmd, SimulateOptions& o) {
  cmd.add_option("--noise", o.noise_ug, "sensor noise density, ug/sqrt(Hz) (two-sided)")
      ->default_val(0.4)
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--seed", o.seed, "random seed (same seed, same run)")->default_val(1);
  cmd.add_option("-o,--out", o.out, "run directory to write")->required();
  cmd.add_flag("--gzip", o.gzip, "write samples.csv.gz");
  cmd.add_flag("--overwrite", o.overwrite, "replace an existing run");
  add_envelope_options(cmd, o.envelope);
  cmd.add_option("--max-duration", o.max_duration_s,
                 "the longest program simulated, s at 100 kHz internal samples (memory: about 0.4 GB a minute)")
      ->default_val(sim::kMaxSimulatedS)
      ->check(CLI::Range(1.0, 14400.0));
}

// Regimes of runs measured by other systems (config/scenarios/README.md has the keys).
void add_regime_options(CLI::App& cmd, SimulateOptions& o) {
  cmd.add_option(
         "--regime", o.regime,
         "klipper-like: a CoreXY head under Klipper's resonance test, head MEMS sensor only (400 Hz .. 3.2 kHz), "
         "two modes 30-80 Hz, per --seed (sim/regimes/klipper_like.hpp); with --hide, --background, --export")
      ->check(CLI::IsMember({sim::kKlipperLike}));
  cmd.add_option("--sensors", o.sensors, "both, head or table: the absent triplex's columns are written empty")
      ->check(CLI::IsMember({"both", "head", "table"}));
  cmd.add_option("--fs", o.fs_hz,
                 "sample rate, Hz: the DAQ's (100 .. 51200, anti-alias filter kept) or, with --mems, the chip's "
                 "output data rate")
      ->check(CLI::Range(100.0, 51200.0));
  std::vector<std::string> chips;
  for (const auto& c : sim::mems_chips()) chips.push_back(c.name);
  cmd.add_option("--mems", o.mems,
                 "both sensors a digital MEMS chip: its resolution, noise and low-pass, no anti-alias filter "
                 "(aliasing), no DAQ delay (sim/sensor/mems_chip.hpp)")
      ->check(CLI::IsMember(chips));
  cmd.add_option("--wrong-mounting", o.wrong_mounting,
                 "the (head, else table) sensor truly mounted as this axes map applied to run.toml's "
                 "to_machine: a sign flip (-x,-y,z), a swap (y,x,z), a mirror (-x,y,z)");
  cmd.add_option("--resonance", o.resonance,
                 "a structural mode FREQ_HZ,DAMPING_RATIO,GAIN,AXIS between the drive and the measured point "
                 "(machine.resonance; repeat for more modes)");
}

// Klipper's resonance test (--program sweep).
void add_sweep_options(CLI::App& cmd, SimulateOptions& o) {
  cmd.add_option("--sweep-axis", o.sweep_axis, "sweep: Klipper's AXIS (x, y, z or dx,dy[,dz])")->default_val("x");
  cmd.add_flag("--klipper-legacy", o.klipper_legacy,
               "sweep: the older Klipper test (max_freq 133.33 Hz, 75 mm/s2 per Hz, no sweeping)");
  cmd.add_option("--freq-start", o.freq_start, "sweep: FREQ_START, Hz (default 5)");
  cmd.add_option("--freq-end", o.freq_end, "sweep: FREQ_END, Hz (default 200, legacy 133.33)");
  cmd.add_option("--hz-per-sec", o.hz_per_sec, "sweep: HZ_PER_SEC (default 1)");
  cmd.add_option("--accel-per-hz", o.accel_per_hz, "sweep: ACCEL_PER_HZ, mm/s2 per Hz (default 60, legacy 75)");
  cmd.add_option("--sweeping-accel", o.sweeping_accel, "sweep: SWEEPING_ACCEL, mm/s2 (default 400, legacy 0)");
  cmd.add_option("--sweeping-period", o.sweeping_period, "sweep: SWEEPING_PERIOD, s (default 1.2, legacy 0)");
}

// The run as another system records it (--export).
void add_export_options(CLI::App& cmd, SimulateOptions& o) {
  cmd.add_option("--export", o.export_to,
                 "also write the run as another system records it, with jittered stamps: 'klipper FILE' (a raw "
                 "accelerometer capture), 'shaketune FILE' (Shake&Tune's .stdata) or 'csv PREFIX' (PREFIX-accel.csv "
                 "and an NC trace); truth.toml [export]")
      ->expected(2);
  cmd.add_option("--export-nc", o.export_nc,
                 "csv export: NC trace as halsampler (PREFIX-nc.txt) or csv (PREFIX-nc.csv)")
      ->check(CLI::IsMember({"halsampler", "csv"}));
  cmd.add_option("--export-offset-s", o.export_offset_s,
                 "export: the capture clock at the run's t = 0, s (klipper-like: drawn)");
  cmd.add_option("--export-jitter-us", o.export_jitter_us,
                 "export: stamp jitter rms, us (default 5 % of a sample; klipper-like: drawn)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--export-lost-batches", o.export_lost_batches, "export: batches lost (gaps)")
      ->check(CLI::Range(0, 1000));
  cmd.add_option("--export-batch", o.export_batch, "export: samples per batch")->check(CLI::Range(1, 4096));
  cmd.add_option("--export-nc-offset-s", o.export_nc_offset_s, "csv export: the NC clock at the run's t = 0, s");
}

// The capture clock and files of --export: drawn for a regime, else from the flags.
ExportRequest export_request(const SimulateOptions& o, double fs) {
  ExportRequest req;
  req.format = parse_export_format(o.export_to[0]), req.target = o.export_to[1], req.nc_format = o.export_nc,
  req.nc_offset_s = o.export_nc_offset_s;
  if (!o.regime.empty()) {
    req.clock = sim::klipper_like_capture_clock(o.seed, fs);
  } else {
    req.clock.offset_s = o.export_offset_s;
    req.clock.jitter_rms_s = o.export_jitter_us >= 0.0 ? o.export_jitter_us * 1e-6 : 0.05 / fs;
    req.clock.lost_batches = o.export_lost_batches, req.clock.batch = o.export_batch, req.clock.seed = o.seed;
  }
  return req;
}

void run_simulate(const SimulateOptions& o, bool program_given) {
  sim::Scenario sc = base_scenario(o, program_given);
  apply_regime_flags(o, sc);
  // The machine's envelope (the scenario's, else the default, the options over it) goes
  // into run.toml; a program beyond it is refused before anything is simulated.
  sc.meta.envelope = envelope_of(o.envelope, sc.meta.envelope.value_or(dsp::WorkEnvelope{}));
  sc.max_duration_s = o.max_duration_s;
  require_within(*sim::scenario_set_point(sc), *sc.meta.envelope,
                 "simulate " + std::string(sc.sweep.on ? "sweep" : dsp::program_kind_name(sc.meta.program.kind)));
  if (!o.export_to.empty()) {
    const double fs = sc.meta.acquisition.fs_hz;
    const std::string line = simulate_with_export(sc, export_request(o, fs), o.out, o.gzip, o.overwrite);
    std::printf("wrote %s (program %s, %.0f Hz)\n%s\n", o.out.c_str(), dsp::program_kind_name(sc.meta.program.kind), fs,
                line.c_str());
    return;
  }
  const dsp::Run run = sim::simulate(sc);
  drivers::write_run(run, o.out, {.gzip = o.gzip, .overwrite = o.overwrite});
  std::printf("wrote %s: %zu samples, %.2f s, program %s\n", o.out.c_str(), run.frames.size(),
              static_cast<double>(run.frames.size()) / run.meta.acquisition.fs_hz,
              dsp::program_kind_name(run.meta.program.kind));
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  auto* cmd = app.add_subcommand("simulate", "Simulate a machine and its sensors; write a recorded run (eical-run/1)");
  add_program_options(*cmd, *o);
  add_output_options(*cmd, *o);
  add_regime_options(*cmd, *o);
  add_sweep_options(*cmd, *o);
  add_export_options(*cmd, *o);
  auto* program_opt = cmd->get_option("--program");
  cmd->callback([o, program_opt] { run_simulate(*o, program_opt->count() > 0); });
}

}  // namespace eical::tools
