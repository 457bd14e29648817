#include "sim/hidden/hidden_effects.hpp"

#include "dsp/core/error.hpp"
#include "dsp/model/effects.hpp"
#include "sim/effects.hpp"
#include "sim/regimes/regimes.hpp"
#include "sim/simulate.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

namespace eical::sim {
namespace {

using dsp::model::Effect;

struct Draw {
  std::mt19937_64 rng;
  explicit Draw(std::uint64_t seed) : rng(seed) {}
  double u(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  double pm(double a) { return u(-a, a); }                                               // ±a, uniform
  double mag(double lo, double hi) { return (u(0, 1) < 0.5 ? -1.0 : 1.0) * u(lo, hi); }  // ±[lo, hi]
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }
};

Eigen::Matrix3d rotation(const Eigen::Vector3d& r) {
  return (Eigen::AngleAxisd(r[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Tolerance-level sensor as the sample runs' truth.toml show it.
void background_sensor(SensorTruth& t, const dsp::SensorSpec& sheet, Draw& d) {
  t.spec = sheet;
  for (int i = 0; i < 3; ++i) {
    t.spec.k1_v_per_g[i] *= 1.0 + d.pm(400e-6);
    t.spec.k2_g_per_g2[i] *= 1.0 + d.pm(0.05);
    t.spec.k3_g_per_g3[i] *= 1.0 + d.pm(0.05);
    t.spec.bias_g[i] += d.pm(2e-3);
  }
  t.spec.tc_k1_ppm_per_c = 70.0 + d.pm(7.0);
  t.spec.tc_bias_ug_per_c = d.mag(85.0, 110.0);
  t.spec.f0_hz *= 1.0 + d.pm(0.01);
  t.spec.zeta += d.pm(0.01);
  t.spec.noise_ug_per_rthz = d.u(0.33, 0.46);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) t.k_cross_g_per_g(i, j) = d.pm(2e-4), t.k_cross2_g_per_g2(i, j) = d.pm(2e-4);
  t.spec.to_machine = sheet.to_machine * rotation(Eigen::Vector3d(d.pm(3e-4), d.pm(3e-4), d.pm(3e-4)));
  t.bias_rw_ug_per_rts = d.u(0.12, 0.3);
  t.temperature.t0_c = d.u(21.0, 24.5);
  t.temperature.rise_c = d.u(0.06, 0.18);
  t.temperature.tau_s = d.u(240.0, 540.0);
}

void program(Scenario& sc, dsp::ProgramKind kind, Draw& d, bool fast) {
  if (kind == dsp::ProgramKind::circle) {
    const double r = std::round(d.u(8.0, 15.0));
    sc = circle_scenario(r, std::round(d.u(2000.0, 3000.0) / 50.0) * 50.0, 5, "ccw", sc.seed);
    sc.meta.psd = psd_config_b(r);
  } else if (kind == dsp::ProgramKind::step) {
    const double to = std::round(d.u(40.0, 60.0));
    const double feed = d.u(0.0, 1.0) < 0.5 ? 3250.0 : 6500.0;
    sc = step_scenario(0.0, to, fast ? 6500.0 : feed, 3, sc.seed);
    sc.meta.program.dwell_s = 0.5;
    // A strip at mid travel, as in the sample step run.
    dsp::PsdSpec s;
    s.measures = "x", s.center_mm[0] = to / 2.0, s.center_mm[1] = 0.0;
    sc.meta.psd = {s};
  } else {
    throw dsp::InputError(std::string("hidden effects: unknown program '") + dsp::program_kind_name(kind) +
                          "' (circle or step)");
  }
}

void background(Scenario& sc, Draw& d) {
  if (d.pick(2) == 1) sc.meta.machine.table_axes = {"x"}, sc.meta.machine.head_axes = {"y", "z"};
  sc.meta.site.latitude_deg = d.u(47.0, 54.0), sc.meta.site.heading_deg = d.u(0.0, 360.0),
  sc.meta.site.g_mps2 = d.u(9.806, 9.813);
  for (int s = 0; s < 2; ++s) background_sensor(sc.truth[s], sc.meta.sensors[s], d);
  sc.coriolis = true;
  const double kv = d.u(31.0, 35.0);
  for (auto& a : sc.machine.servo) a = AxisServo{kv + d.pm(0.05), 0.99, 0.0};
  auto& m = sc.machine;
  for (int a = 0; a < 3; ++a) {
    m.backlash_um[a] = d.u(0.0, 0.3);
    m.spike[a] = ReversalSpike{d.u(0.0, 0.16), d.u(11.0, 20.0)};
    m.scale_ppm[a] = d.pm(3.0);
    m.cyclic[a] = CyclicError{d.u(0.0, 0.1), 10.0, d.u(0.0, 360.0)};
  }
  m.squareness_urad[0] = d.pm(2.5);
  const double span = sc.meta.program.kind == dsp::ProgramKind::circle ? sc.meta.program.radius_mm : 50.0;
  m.straightness[0] = Straightness{1, d.pm(0.26), {-span, span}};
  m.straightness[1] = Straightness{0, d.pm(0.26), {-span, span}};
  sc.daq.group_delay_samples = sc.meta.acquisition.daq_group_delay_samples;
  for (auto& o : sc.daq.offset_counts) o = static_cast<std::int64_t>(d.pm(2500.0));
  sc.daq.noise_nv_per_rthz = 200.0;
  sc.psd.assign(sc.meta.psd.size(), PsdTruth{});
  for (auto& p : sc.psd) p.nonlinearity = d.pm(1e-4);
  sc.meta.reference = dsp::Reference{"KGM182", {"x", "y"}};
  for (int a = 0; a < 2; ++a) {
    sc.reference.scale_ppm[a] = d.pm(5.0);
    sc.reference.interp_nm[a][0] = d.u(5.0, 20.0), sc.reference.interp_nm[a][1] = d.u(1.0, 4.5);
    sc.reference.interp_phase_deg[a][0] = d.u(0.0, 360.0), sc.reference.interp_phase_deg[a][1] = d.u(0.0, 360.0);
  }
  sc.effects_background = {
      "sensor.scale",           "sensor.nonlinearity",    "sensor.cross_coupling",    "sensor.misalignment",
      "sensor.dynamics",        "sensor.bias_drift",      "sensor.scale_temperature", "site.coriolis",
      "machine.backlash",       "machine.reversal_spike", "machine.servo_mismatch",   "machine.squareness",
      "machine.scale_mismatch", "machine.cyclic_error",   "machine.straightness"};
}

// The sensor an effect goes into: one that moves an axis of the program.
int moving_sensor(const Scenario& sc, Draw& d) {
  const bool head_moves = std::find(sc.meta.machine.head_axes.begin(), sc.meta.machine.head_axes.end(), "y") !=
                          sc.meta.machine.head_axes.end();
  const bool circle = sc.meta.program.kind == dsp::ProgramKind::circle;
  const int pick = d.pick(2);              // drawn always: the sizes after it do not depend on the program
  return circle && head_moves ? pick : 0;  // x (and y) are the table's otherwise
}

int moving_axis(const Scenario& sc, Draw& d) {
  const int pick = d.pick(2);
  return sc.meta.program.kind == dsp::ProgramKind::circle ? pick : 0;
}

[[noreturn]] void unknown_effect(const std::string& e) {
  throw dsp::InputError("hidden effects: unknown effect '" + e + "'");
}

// sensor.*: into the sensor that moves an axis of the program (both sensors' cases warm).
void inject_sensor(Scenario& sc, Effect e, Draw& d) {
  if (e == Effect::sensor_scale) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    for (int i = 0; i < 3; ++i)
      t.spec.k1_v_per_g[i] = sc.meta.sensors[&t - sc.truth].k1_v_per_g[i] * (1.0 + d.mag(2000e-6, 5000e-6));
  } else if (e == Effect::sensor_bias_drift) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    if (sc.meta.program.kind == dsp::ProgramKind::step)
      t.bias_step_ug = d.u(6.0, 15.0);
    else
      t.bias_drift_ug_per_s = d.mag(0.3, 1.0);
  } else if (e == Effect::sensor_nonlinearity) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    for (int i = 0; i < 3; ++i) t.spec.k2_g_per_g2[i] += d.mag(2e-3, 4e-3), t.spec.k3_g_per_g3[i] += d.mag(2e-3, 4e-3);
  } else if (e == Effect::sensor_cross_coupling) {
    // Sensing axes not square to each other: each pair responds to the other alike (the
    // antisymmetric part of a cross-axis matrix is a rotation: sensor.misalignment).
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        const double k = d.mag(0.8e-3, 2e-3);
        t.k_cross_g_per_g(i, j) += k, t.k_cross_g_per_g(j, i) += k;
      }
  } else if (e == Effect::sensor_misalignment) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    Eigen::Vector3d r(d.pm(3e-4), d.pm(3e-4), d.pm(3e-4));
    r[d.pick(3)] = d.mag(1.5e-3, 4e-3);
    t.spec.to_machine = sc.meta.sensors[&t - sc.truth].to_machine * rotation(r);
  } else if (e == Effect::sensor_dynamics) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    t.spec.zeta = sc.meta.sensors[&t - sc.truth].zeta + d.mag(0.08, 0.15);
    t.spec.f0_hz = sc.meta.sensors[&t - sc.truth].f0_hz * (1.0 + d.pm(0.06));
  } else if (e == Effect::sensor_damping_amplitude) {
    SensorTruth& t = sc.truth[moving_sensor(sc, d)];
    t.zeta_per_g = d.u(0.5, 1.5);
  } else if (e == Effect::sensor_scale_temperature) {
    // The cases warm by a degree or more, and their coefficients are off the data sheet's
    // (which the pipeline compensates with) by about the data sheet's own size.
    for (int s = 0; s < 2; ++s) {
      SensorTruth& t = sc.truth[s];
      t.temperature.rise_c = d.u(1.0, 3.0), t.temperature.tau_s = d.u(15.0, 40.0);
      t.spec.tc_bias_ug_per_c = sc.meta.sensors[s].tc_bias_ug_per_c + d.mag(100.0, 200.0);
      t.spec.tc_k1_ppm_per_c = sc.meta.sensors[s].tc_k1_ppm_per_c + d.mag(50.0, 150.0);
    }
  } else {
    unknown_effect(std::string(dsp::model::name(e)));
  }
}

// The vibration common to table and head, and the head's against the table.
void inject_vibration(Scenario& sc, Effect e, Draw& d) {
  if (e == Effect::machine_common_vibration) {
    auto& v = sc.common_vibration;
    Tone drive;
    drive.freq_hz = 100.0, drive.amp_mg = Eigen::Vector3d(d.u(1.0, 4.0), d.u(1.0, 3.0), d.u(0.5, 1.5)),
    drive.phase_deg = d.u(0, 360);
    Tone floor;
    floor.freq_hz = d.u(15.0, 40.0), floor.amp_mg = Eigen::Vector3d(d.u(0.1, 0.4), d.u(0.1, 0.4), d.u(0.05, 0.2)),
    floor.phase_deg = d.u(0, 360);
    v.tones = {drive, floor};
    v.broadband_rms_mg = Eigen::Vector3d(d.u(0.4, 1.5), d.u(0.4, 1.5), d.u(0.4, 1.5));
    v.mode.freq_hz = d.u(8.0, 11.0), v.mode.zeta = d.u(0.03, 0.05),
    v.mode.gain = Eigen::Vector3d::Constant(d.u(0.005, 0.015));
  } else if (e == Effect::machine_differential_vibration) {
    sc.differential_vibration.freq_hz = d.u(12.0, 25.0), sc.differential_vibration.zeta = d.u(0.03, 0.06);
    sc.differential_vibration.gain = Eigen::Vector3d::Constant(d.u(0.01, 0.03));
    Tone t;
    t.freq_hz = d.u(30.0, 60.0), t.amp_mg = Eigen::Vector3d(d.u(0.5, 1.5), d.u(0.5, 1.5), d.u(0.2, 0.5)),
    t.phase_deg = d.u(0, 360);
    sc.differential_tones = {t};
  } else {
    unknown_effect(std::string(dsp::model::name(e)));
  }
}

// The errors of an axis the program moves (squareness: of the xy pair).
void inject_machine(Scenario& sc, Effect e, Draw& d) {
  auto& m = sc.machine;
  if (e == Effect::machine_backlash) {
    m.backlash_um[moving_axis(sc, d)] = d.u(3.0, 10.0);
  } else if (e == Effect::machine_reversal_spike) {
    m.spike[moving_axis(sc, d)] = ReversalSpike{d.u(2.0, 6.0), d.u(10.0, 25.0)};
  } else if (e == Effect::machine_servo_mismatch) {
    AxisServo& a = m.servo[moving_axis(sc, d)];
    a.kv_per_s *= d.u(0.6, 0.85), a.feedforward = d.u(0.95, 0.98);
  } else if (e == Effect::machine_squareness) {
    m.squareness_urad[0] = d.mag(15.0, 50.0);
  } else if (e == Effect::machine_scale_mismatch) {
    m.scale_ppm[moving_axis(sc, d)] = d.mag(20.0, 60.0);
  } else if (e == Effect::machine_cyclic_error) {
    m.cyclic[moving_axis(sc, d)] = CyclicError{d.u(1.0, 3.0), d.pick(2) ? 5.0 : 10.0, d.u(0.0, 360.0)};
  } else if (e == Effect::machine_straightness) {
    const int a = moving_axis(sc, d);
    const double span = sc.meta.program.kind == dsp::ProgramKind::circle ? sc.meta.program.radius_mm
                                                                         : sc.meta.program.targets_mm.back();
    m.straightness[a] = Straightness{
        a == 0 ? 1 : 0, d.mag(2.0, 5.0), {sc.meta.program.kind == dsp::ProgramKind::circle ? -span : 0.0, span}};
  } else if (e == Effect::machine_stick_slip) {
    m.stick_slip[moving_axis(sc, d)] = StickSlip{d.u(1.0, 3.0), d.u(100.0, 200.0), 2.0};
  } else if (e == Effect::machine_resonance) {
    // A lightly damped mode between the moving axis' drive and its part's measured point,
    // rung by every acceleration ramp of the program.
    const int a = moving_axis(sc, d);
    const auto& head = sc.meta.machine.head_axes;
    StructuralMode mode;
    mode.frequency_hz = d.u(30.0, 120.0), mode.damping_ratio = d.u(0.01, 0.05), mode.gain = d.u(0.05, 0.2);
    mode.direction = Eigen::Vector3d::Unit(a);
    sc.resonance.modes = {mode};
    sc.resonance.part =
        std::find(head.begin(), head.end(), std::string(1, static_cast<char>('x' + a))) != head.end() ? 1 : 0;
    // Measured by the moving part's sensor alone (a machine with one sensor, as the printers
    // under Klipper): with both, the same mode is the head moving against the table, which
    // explain names machine.differential_vibration (run-format.md).
    set_sensors_present(sc, sc.resonance.part == 1 ? "head" : "table");
  } else {
    unknown_effect(std::string(dsp::model::name(e)));
  }
}

// The effect e on top of the background, its sizes drawn from d.
void inject(Scenario& sc, const std::string& name, Draw& d) {
  const std::optional<Effect> e = dsp::model::effect_named(name);
  if (!e) unknown_effect(name);
  switch (dsp::model::info(*e).side) {
    case dsp::model::EffectSide::sensor: return inject_sensor(sc, *e, d);
    case dsp::model::EffectSide::daq:
      sc.daq.group_delay_samples = sc.meta.acquisition.daq_group_delay_samples + d.mag(0.8, 2.0);
      if (d.pick(2) == 1) sc.daq.skew_head_samples = d.mag(0.3, 1.0);
      return;
    case dsp::model::EffectSide::site: sc.coriolis = true; return;
    case dsp::model::EffectSide::machine: break;
  }
  if (*e == Effect::machine_common_vibration || *e == Effect::machine_differential_vibration)
    return inject_vibration(sc, *e, d);
  inject_machine(sc, *e, d);
}

}  // namespace

const std::vector<std::string>& hidden_programs() {
  static const std::vector<std::string> p = {"circle", "step"};
  return p;
}

// Every effect of the table can be hidden (the simulator's own list of them).
const std::vector<std::string>& hideable_effects() { return effect_names(); }

dsp::ProgramKind program_for(const std::string& effect) {
  // What a long straight move shows best: the sensors' own errors, vibration, a scale.
  static constexpr Effect kStep[] = {Effect::sensor_scale,
                                     Effect::sensor_bias_drift,
                                     Effect::sensor_nonlinearity,
                                     Effect::sensor_dynamics,
                                     Effect::sensor_damping_amplitude,
                                     Effect::sensor_scale_temperature,
                                     Effect::machine_common_vibration,
                                     Effect::machine_differential_vibration,
                                     Effect::machine_scale_mismatch,
                                     Effect::site_coriolis,
                                     Effect::machine_resonance};
  const std::optional<Effect> e = dsp::model::effect_named(effect);
  return e && std::find(std::begin(kStep), std::end(kStep), *e) != std::end(kStep) ? dsp::ProgramKind::step
                                                                                   : dsp::ProgramKind::circle;
}

dsp::ProgramKind program_for(const std::vector<std::string>& effects) {
  for (const auto& e : effects)
    if (program_for(e) == dsp::ProgramKind::circle) return dsp::ProgramKind::circle;
  return effects.empty() ? dsp::ProgramKind::circle : dsp::ProgramKind::step;
}

Scenario hidden_effect_scenario(const std::vector<std::string>& effects, dsp::ProgramKind kind, std::uint64_t seed) {
  Draw d(stream_seed(seed, 7001));
  Scenario sc;
  sc.seed = seed;
  // Damping that grows with |a| and nonlinearity show with the acceleration of a fast move
  // (the sample run of sensor.damping_amplitude: 6.5 m/min).
  auto has = [&](Effect x) {
    return std::any_of(effects.begin(), effects.end(),
                       [&](const std::string& e) { return dsp::model::effect_named(e) == x; });
  };
  // The program draws from its own stream: one seed is one machine (sensors, errors),
  // whichever program measures it.
  Draw dp(stream_seed(seed, 7002));
  program(sc, kind, dp, has(Effect::sensor_damping_amplitude) || has(Effect::sensor_nonlinearity));
  background(sc, d);
  // Cross coupling differs from a rotated mounting only where one sensor moves two axes.
  if (has(Effect::sensor_cross_coupling)) sc.meta.machine.table_axes = {"x", "y"}, sc.meta.machine.head_axes = {"z"};
  for (const auto& e : effects) {
    // Each effect from its own stream: its size does not depend on what else is hidden.
    const auto& names = hideable_effects();
    Draw de(
        stream_seed(seed, 7100 + static_cast<std::uint64_t>(std::find(names.begin(), names.end(), e) - names.begin())));
    inject(sc, e, de);
    sc.effects_present.push_back(e);
    sc.effects_background.erase(std::remove(sc.effects_background.begin(), sc.effects_background.end(), e),
                                sc.effects_background.end());
  }
  std::string name = effects.empty() ? "baseline" : effects.front();
  for (std::size_t i = 1; i < effects.size(); ++i) name += "+" + effects[i];
  sc.name = name;
  sc.meta.id = "hidden-" + name + "-" + dsp::program_kind_name(kind) + "-s" + std::to_string(seed);
  sc.description = (effects.empty() ? std::string("no effect") : name) + " hidden among tolerance-level deviations, " +
                   dsp::program_kind_name(kind) + " program";
  return sc;
}

}  // namespace eical::sim
