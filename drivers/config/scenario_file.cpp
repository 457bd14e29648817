#include "drivers/config/scenario_file.hpp"
#include "drivers/config/strict_eigen.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"
#include "dsp/model/effects.hpp"
#include "sim/effects.hpp"
#include "sim/gcode/canonical.hpp"
#include "sim/gcode/parser.hpp"
#include "sim/regimes/regimes.hpp"
#include "sim/sensor/axes_map.hpp"
#include "sim/sensor/mems_chip.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

namespace eical::drivers {
namespace {

using dsp::model::Effect;

int axis_of(StrictTable& t, std::string_view key) {
  const std::string a = t.choice(key, {"x", "y", "z"}, "");
  if (a.empty()) t.fail(key, "required: \"x\", \"y\" or \"z\"");
  return a[0] - 'x';
}

Eigen::Matrix3d mat3(StrictTable& t, std::string_view key) {
  if (!t.has(key)) return Eigen::Matrix3d::Zero();
  const auto m = t.matrix(key, 3, 3);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  return r;
}

double positive(StrictTable& t, std::string_view key, double fallback) {
  const double v = t.number(key, fallback);
  if (!(v > 0.0)) t.fail(key, "must be positive");
  return v;
}

// The sensors an effect applies to.
std::vector<int> sensors_of(StrictTable& t) {
  const std::string s = t.choice("sensor", {"table", "head", "both"}, "both");
  if (s == "table") return {0};
  if (s == "head") return {1};
  return {0, 1};
}

void read_sensor_effect(Effect e, StrictTable& t, sim::Scenario& sc) {
  for (int s : sensors_of(t)) {
    sim::SensorTruth& st = sc.truth[s];
    const dsp::SensorSpec& nominal = sc.meta.sensors[s];
    if (e == Effect::sensor_scale) {
      if (t.has("scale_ppm")) {
        const Eigen::Vector3d ppm = vec3_or(t, "scale_ppm", Eigen::Vector3d::Zero());
        st.spec.k1_v_per_g = nominal.k1_v_per_g.cwiseProduct(Eigen::Vector3d::Ones() + ppm * 1e-6);
        if (t.has("k1_v_per_g")) t.fail("k1_v_per_g", "give either scale_ppm or k1_v_per_g, not both");
      } else {
        st.spec.k1_v_per_g = vec3_or(t, "k1_v_per_g", nominal.k1_v_per_g);
      }
    } else if (e == Effect::sensor_bias_drift) {
      st.bias_rw_ug_per_rts = t.number("rw_ug_per_rts", 0.0);
      st.bias_step_ug = t.number("step_ug", 0.0);
      st.bias_drift_ug_per_s = t.number("drift_ug_per_s", 0.0);
    } else if (e == Effect::sensor_nonlinearity) {
      st.spec.k2_g_per_g2 = vec3_or(t, "k2_g_per_g2", nominal.k2_g_per_g2);
      st.spec.k3_g_per_g3 = vec3_or(t, "k3_g_per_g3", nominal.k3_g_per_g3);
    } else if (e == Effect::sensor_cross_coupling) {
      st.k_cross_g_per_g = mat3(t, "k_cross_g_per_g");
      st.k_cross2_g_per_g2 = mat3(t, "k_cross2_g_per_g2");
    } else if (e == Effect::sensor_misalignment) {
      const Eigen::Vector3d r = vec3_or(t, "misalignment_mrad", Eigen::Vector3d::Zero()) * 1e-3;
      // Rotation about the sensor axes, applied after the nominal mounting.
      const Eigen::Matrix3d rot =
          (Eigen::AngleAxisd(r[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r[1], Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(r[0], Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
      st.spec.to_machine = nominal.to_machine * rot;
      // A sign flip, swap or mirror on top (Klipper's axes_map notation).
      if (t.has("axes_map")) {
        const std::string map = t.string("axes_map");
        try {
          st.spec.to_machine = sim::axes_map_matrix(map, "") * st.spec.to_machine;
        } catch (const dsp::InputError& bad) {
          t.fail("axes_map", bad.what());
        }
        st.axes_map = map;
      }
    } else if (e == Effect::sensor_dynamics) {
      st.spec.f0_hz = positive(t, "f0_hz", nominal.f0_hz);
      st.spec.zeta = positive(t, "zeta", nominal.zeta);
    } else if (e == Effect::sensor_damping_amplitude) {
      st.spec.zeta = positive(t, "zeta0", st.spec.zeta);
      st.zeta_per_g = t.number("zeta_per_g");
    } else if (e == Effect::sensor_scale_temperature) {
      st.temperature.t0_c = t.number("t0_c", st.temperature.t0_c);
      st.temperature.rise_c = t.number("rise_c");
      st.temperature.tau_s = positive(t, "tau_s", st.temperature.tau_s);
      st.spec.tc_k1_ppm_per_c = t.number("tc_k1_ppm_per_c", st.spec.tc_k1_ppm_per_c);
      st.spec.tc_bias_ug_per_c = t.number("tc_bias_ug_per_c", st.spec.tc_bias_ug_per_c);
    }
  }
}

// [[…tones]]: freq_hz, amp_mg [3], phase_deg.
std::vector<sim::Tone> read_tones(StrictTable& t) {
  std::vector<sim::Tone> tones;
  for (StrictTable tone : t.tables("tones")) {
    sim::Tone x;
    x.freq_hz = positive(tone, "freq_hz", x.freq_hz);
    x.amp_mg = vec3_or(tone, "amp_mg", Eigen::Vector3d::Zero());
    x.phase_deg = tone.number("phase_deg", 0.0);
    tone.finish();
    tones.push_back(x);
  }
  return tones;
}

sim::DriveMode read_mode(StrictTable t, const std::string& gain_key = "gain") {
  sim::DriveMode m;
  m.freq_hz = positive(t, "freq_hz", m.freq_hz);
  m.zeta = positive(t, "zeta", m.zeta);
  m.gain = vec3_or(t, gain_key, Eigen::Vector3d::Zero());
  t.finish();
  return m;
}

void read_machine_effect(Effect e, StrictTable& t, sim::Scenario& sc) {
  sim::MachineErrors& m = sc.machine;
  if (e == Effect::machine_common_vibration) {
    sim::CommonVibration& v = sc.common_vibration;
    v.broadband_rms_mg = vec3_or(t, "broadband_rms_mg", Eigen::Vector3d::Zero());
    if (t.has("band_hz")) {
      const auto b = t.numbers("band_hz", 2);
      if (!(b[0] > 0.0 && b[1] > b[0])) t.fail("band_hz", "must be [low, high] with 0 < low < high");
      v.band_hz[0] = b[0], v.band_hz[1] = b[1];
    }
    v.tones = read_tones(t);
    if (auto mode = t.optional_table("mode")) v.mode = read_mode(*mode);
    if (!v.on()) t.fail("broadband_rms_mg", "common vibration needs tones, broadband_rms_mg or a mode with gain");
  } else if (e == Effect::machine_differential_vibration) {
    sc.differential_vibration.freq_hz = positive(t, "freq_hz", 9.0);
    sc.differential_vibration.zeta = positive(t, "zeta", 0.03);
    sc.differential_vibration.gain = vec3_or(t, "gain", Eigen::Vector3d::Zero());
    sc.differential_tones = read_tones(t);
    if (sc.differential_vibration.gain.squaredNorm() == 0.0 && sc.differential_tones.empty())
      t.fail("gain", "differential vibration needs a mode gain or tones");
  } else if (e == Effect::machine_resonance) {
    sc.resonance.part = t.choice("part", {"table", "head"}, "head") == "head" ? 1 : 0;
    sc.resonance.modes.clear();
    for (StrictTable mt : t.tables("modes")) {
      sim::StructuralMode md;
      md.frequency_hz = positive(mt, "frequency_hz", md.frequency_hz);
      md.damping_ratio = positive(mt, "damping_ratio", md.damping_ratio);
      if (!(md.damping_ratio < 1.0)) mt.fail("damping_ratio", "must be below 1 (a lightly damped mode: 0.01 .. 0.05)");
      md.gain = mt.number("gain");
      md.direction = vec3_or(mt, "direction", md.direction);
      if (!(md.direction.norm() > 0.0)) mt.fail("direction", "must not be the zero vector");
      mt.finish();
      sc.resonance.modes.push_back(md);
    }
    if (!sc.resonance.on())
      t.fail("modes", "machine.resonance needs at least one [[…modes]] table with a non-zero gain");
  } else if (e == Effect::machine_backlash) {
    m.backlash_um[axis_of(t, "axis")] = t.number("value_um");
  } else if (e == Effect::machine_reversal_spike) {
    const int a = axis_of(t, "axis");
    m.spike[a].amp_um = t.number("amp_um");
    m.spike[a].tau_ms = positive(t, "tau_ms", m.spike[a].tau_ms);
  } else if (e == Effect::machine_servo_mismatch) {
    // Needs a position loop on every axis: without [servo.*] the axes get Kv 30/s and
    // 90 % velocity feed-forward, then the named axis its own Kv.
    for (auto& s : m.servo)
      if (!(s.kv_per_s > 0.0)) s.kv_per_s = 30.0, s.feedforward = 0.9;
    const int a = axis_of(t, "axis");
    m.servo[a].kv_per_s = positive(t, "kv_per_s", m.servo[a].kv_per_s);
    m.servo[a].feedforward = t.number("feedforward", m.servo[a].feedforward);
  } else if (e == Effect::machine_squareness) {
    const std::string plane = t.choice("plane", {"xy", "yz", "zx"}, "xy");
    m.squareness_urad[plane == "xy" ? 0 : (plane == "yz" ? 1 : 2)] = t.number("value_urad");
  } else if (e == Effect::machine_scale_mismatch) {
    m.scale_ppm[axis_of(t, "axis")] = t.number("value_ppm");
  } else if (e == Effect::machine_cyclic_error) {
    const int a = axis_of(t, "axis");
    m.cyclic[a].amp_um = t.number("amp_um");
    m.cyclic[a].pitch_mm = positive(t, "pitch_mm", m.cyclic[a].pitch_mm);
    m.cyclic[a].phase_deg = t.number("phase_deg", 0.0);
  } else if (e == Effect::machine_straightness) {
    const int a = axis_of(t, "axis");
    const int d = axis_of(t, "direction");
    if (d == a) t.fail("direction", "must differ from the axis");
    m.straightness[a].direction = d;
    m.straightness[a].bow_um = t.number("bow_um");
    if (t.has("span_mm")) {
      const auto s = t.numbers("span_mm", 2);
      if (!(s[1] > s[0])) t.fail("span_mm", "must be [from, to] with from < to");
      m.straightness[a].span_mm[0] = s[0], m.straightness[a].span_mm[1] = s[1];
    }
  } else if (e == Effect::machine_stick_slip) {
    const int a = axis_of(t, "axis");
    m.stick_slip[a].amp_um = t.number("amp_um");
    m.stick_slip[a].below_mm_min = positive(t, "below_mm_min", m.stick_slip[a].below_mm_min);
    m.stick_slip[a].slip_ms = positive(t, "slip_ms", m.stick_slip[a].slip_ms);
  }
}

void read_effect(Effect e, StrictTable t, sim::Scenario& sc) {
  switch (dsp::model::info(e).side) {
    case dsp::model::EffectSide::sensor: read_sensor_effect(e, t, sc); break;
    case dsp::model::EffectSide::daq:
      sc.daq.group_delay_samples = t.number("group_delay_samples", sc.meta.acquisition.daq_group_delay_samples);
      sc.daq.skew_head_samples = t.number("skew_head_samples", sc.meta.acquisition.daq_skew_head_samples);
      if (sc.daq.group_delay_samples < 0.0) t.fail("group_delay_samples", "must not be negative");
      break;
    case dsp::model::EffectSide::site: sc.coriolis = t.boolean("on", true); break;
    case dsp::model::EffectSide::machine: read_machine_effect(e, t, sc); break;
  }
  t.finish();
}

// [mems]: a digital MEMS chip on both sensors (sim/regimes apply_mems): a known chip and
// any of its figures overridden, the true bias beside it.
void read_mems(StrictTable t, sim::Scenario& sc) {
  sim::MemsChip chip = sim::mems_chip(t.choice(
      "chip",
      [] {
        std::vector<std::string> names;
        for (const auto& c : sim::mems_chips()) names.push_back(c.name);
        return names;
      }(),
      "adxl345"));
  chip.fs_hz = positive(t, "fs_hz", chip.fs_hz);
  chip.bits = t.int32("bits", chip.bits);
  if (chip.bits < 8 || chip.bits > 24) t.fail("bits", "must be 8..24");
  chip.range_g = positive(t, "range_g", chip.range_g);
  chip.noise_ug_per_rthz = t.number("noise_ug_per_rthz", chip.noise_ug_per_rthz);
  if (chip.noise_ug_per_rthz < 0.0) t.fail("noise_ug_per_rthz", "must not be negative");
  if (t.has("bandwidth_hz"))
    chip.bandwidth_hz = positive(t, "bandwidth_hz", chip.bandwidth_hz), chip.bandwidth_follows_odr = false;
  if (!(chip.fs_hz >= 100.0 && chip.fs_hz <= 51200.0)) t.fail("fs_hz", "must be 100 .. 51200 Hz");
  const Eigen::Vector3d bias_g = vec3_or(t, "bias_mg", Eigen::Vector3d::Zero()) * 1e-3;
  t.finish();
  sim::apply_mems(sc, chip, chip.fs_hz, bias_g);
}

// [sweep]: Klipper's resonance test instead of the G-code program.
void read_sweep(StrictTable t, sim::Scenario& sc) {
  const std::string preset = t.choice("preset", {"current", "legacy"}, "current");
  sim::nc::KlipperTest k = preset == "legacy" ? sim::nc::KlipperTest::legacy() : sim::nc::KlipperTest::current();
  const std::string axis = t.string("axis", "x");
  try {
    sc.sweep.direction = sim::nc::test_direction(axis, "axis");
  } catch (const dsp::InputError& e) {
    t.fail("axis", e.what());
  }
  k.freq_start_hz = t.number("freq_start_hz", k.freq_start_hz);
  k.freq_end_hz = t.number("freq_end_hz", k.freq_end_hz);
  k.accel_per_hz = t.number("accel_per_hz", k.accel_per_hz);
  k.hz_per_sec = t.number("hz_per_sec", k.hz_per_sec);
  k.sweeping_accel_mm_s2 = t.number("sweeping_accel_mm_s2", k.sweeping_accel_mm_s2);
  k.sweeping_period_s = t.number("sweeping_period_s", k.sweeping_period_s);
  k.stop_accel_mm_s2 = t.number("stop_accel_mm_s2", k.stop_accel_mm_s2);
  if (const std::string why = k.invalid_reason(); !why.empty()) {
    // The key the reason is about (invalid_reason names it first).
    const char* key = why.rfind("freq_start", 0) == 0        ? "freq_start_hz"
                      : why.rfind("freq_end", 0) == 0        ? "freq_end_hz"
                      : why.rfind("accel_per_hz", 0) == 0    ? "accel_per_hz"
                      : why.rfind("hz_per_sec", 0) == 0      ? "hz_per_sec"
                      : why.rfind("sweeping_period", 0) == 0 ? "sweeping_period_s"
                      : why.rfind("sweeping", 0) == 0        ? "sweeping_accel_mm_s2"
                      : why.rfind("the stop", 0) == 0        ? "stop_accel_mm_s2"
                                                             : "preset";
    t.fail(t.has(key) ? key : "preset", why);
  }
  sc.sweep.start_mm = vec3_or(t, "start_mm", Eigen::Vector3d::Zero());
  sc.sweep.lead_in_s = t.number("lead_in_s", 0.0);
  sc.sweep.tail_s = t.number("tail_s", 0.0);
  if (sc.sweep.lead_in_s < 0.0 || sc.sweep.tail_s < 0.0)
    t.fail(sc.sweep.lead_in_s < 0.0 ? "lead_in_s" : "tail_s", "must not be negative");
  t.finish();
  sc.sweep.on = true;
  sc.sweep.test = k;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  if (!in) throw dsp::InputError(p.string() + ": cannot read the G-code file");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// The file's identity: format, name, seed, oversampling, noise, run id.
void read_header(StrictTable& root, sim::Scenario& sc) {
  if (root.string("format") != "eical-scenario/1") root.fail("format", "expected \"eical-scenario/1\"");
  sc.name = root.string("name", "scenario");
  sc.description = root.string("description", "");
  sc.seed = static_cast<std::uint64_t>(root.integer("seed", 1));
  sc.oversample = root.int32("oversample", 10);
  if (sc.oversample < 1 || sc.oversample > 100) root.fail("oversample", "must be 1..100");
  sc.noise = root.boolean("noise", true);
  sc.meta.id = root.string("id", "");
}

// Without an `id`, the run's id names the scenario, its program and seed: one machine's
// scenario runs several programs (identification, circle, positioning), and the history
// keeps runs by id, so an id without the program would take the second for the first.
void default_run_id(sim::Scenario& sc) {
  if (!sc.meta.id.empty()) return;
  const std::string kind = dsp::program_kind_name(sc.meta.program.kind);
  sc.meta.id = "sim-" + sc.name + (kind == sc.name ? "" : "-" + kind) + "-s" + std::to_string(sc.seed);
}

// What eical is told (run.toml's sections); the truth starts from it.
void read_told(StrictTable& root, sim::Scenario& sc) {
  if (auto t = root.optional_table("acquisition")) sc.meta.acquisition = read_acquisition(*t);
  if (auto t = root.optional_table("site")) sc.meta.site = read_site(*t);
  if (auto t = root.optional_table("machine")) sc.meta.machine = read_machine(*t);
  if (auto t = root.optional_table("envelope")) sc.meta.envelope = read_envelope(*t);
  if (auto sensors = root.optional_table("sensors")) {
    if (auto t = sensors->optional_table("table")) sc.meta.sensors[0] = read_sensor(*t);
    if (auto t = sensors->optional_table("head")) sc.meta.sensors[1] = read_sensor(*t);
    sensors->finish();
  }
  for (int s = 0; s < 2; ++s)
    sc.truth[s].spec = sc.meta.sensors[s], sc.truth[s].zeta_per_g = sc.meta.sensors[s].zeta_per_g;
  sc.daq.group_delay_samples = sc.meta.acquisition.daq_group_delay_samples;
  sc.daq.skew_head_samples = sc.meta.acquisition.daq_skew_head_samples;
}

// [truth.sensors.*] / [truth.daq]: the true sensors and DAQ in full (run.toml's sensor
// keys, starting from what eical is told) — what eical explain writes to reproduce a run.
void read_truth(StrictTable& truth, sim::Scenario& sc) {
  if (auto sensors = truth.optional_table("sensors")) {
    for (int s = 0; s < 2; ++s)
      if (auto t = sensors->optional_table(s == 0 ? "table" : "head")) {
        sc.truth[s].spec = read_sensor(*t, sc.meta.sensors[s]);
        sc.truth[s].zeta_per_g = sc.truth[s].spec.zeta_per_g;
      }
    sensors->finish();
  }
  if (auto d = truth.optional_table("daq")) {
    sc.daq.group_delay_samples = d->number("group_delay_samples", sc.daq.group_delay_samples);
    sc.daq.skew_head_samples = d->number("skew_head_samples", sc.daq.skew_head_samples);
    if (!(sc.daq.group_delay_samples >= 0.0)) d->fail("group_delay_samples", "must not be negative");
    d->finish();
  }
  truth.finish();
}

// [sweep] and [program]: with a [sweep] the program is the test; [program] may still name
// its kind. A G-code file is read relative to the scenario's folder.
// The G-code file is in `dialect` and read here, where its name is known: its errors name
// it, a file without motion is refused, and the program is kept in the canonical form
// (sim/gcode/canonical.hpp). Inline `gcode` is run.toml's, canonical already.
void read_motion(StrictTable& root, const std::string& path, sim::gcode::Dialect dialect, sim::Scenario& sc) {
  if (auto t = root.optional_table("sweep")) read_sweep(*t, sc);
  bool gcode_file_read = false;
  if (sc.sweep.on && !sc.meta.envelope) sc.meta.envelope = sim::corexy_printer_envelope();  // Klipper's machine
  if (auto program = sc.sweep.on ? root.optional_table("program") : std::optional<StrictTable>(root.table("program"))) {
    const std::string gcode_file = program->string("gcode_file", "");
    sc.meta.program = read_program(*program);  // the copy knows gcode_file is used
    if (!gcode_file.empty()) {
      gcode_file_read = true;
      if (sc.sweep.on) program->fail("gcode_file", "a [sweep] scenario runs Klipper's test, not a G-code program");
      const std::filesystem::path p = std::filesystem::path(path).parent_path() / gcode_file;
      sc.meta.program.gcode = sim::gcode::canonical_gcode(read_text(p), p.string(), dialect);
    } else if (!sc.meta.program.gcode.empty()) {
      (void)sim::gcode::parse(sc.meta.program.gcode, path + " [program] gcode");
    }
  } else {
    sc.meta.program.kind = dsp::ProgramKind::freeform;
  }
  if (dialect != sim::gcode::Dialect::linuxcnc && !gcode_file_read)
    throw dsp::InputError(path + ": a G-code dialect (" + sim::gcode::dialect_name(dialect) +
                          ") is for a [program] gcode_file, and this scenario has none");
}

// [[psd]]: each strip as run.toml has it, and its truth.
void read_psd_strips(StrictTable& root, sim::Scenario& sc) {
  for (StrictTable p : root.tables("psd")) {
    sim::PsdTruth pt;
    pt.spot_mm = positive(p, "spot_mm", pt.spot_mm);
    pt.full_scale_v = positive(p, "full_scale_v", pt.full_scale_v);
    pt.nonlinearity = p.number("nonlinearity", pt.nonlinearity);
    pt.noise_v_per_rthz = p.number("noise_v_per_rthz", pt.noise_v_per_rthz);
    sc.meta.psd.push_back(read_psd(p));
    sc.psd.push_back(pt);
  }
  if (sc.meta.psd.size() > static_cast<std::size_t>(dsp::kMaxPsd))
    root.fail("psd", "at most " + std::to_string(dsp::kMaxPsd) + " strips");
}

// A 3 × 2 matrix key (per axis, per harmonic) into dst when present.
void read_3x2(StrictTable& r, std::string_view key, double (&dst)[3][2]) {
  if (!r.has(key)) return;
  const auto m = r.matrix(key, 3, 2);
  for (int a = 0; a < 3; ++a)
    for (int h = 0; h < 2; ++h) dst[a][h] = m[static_cast<std::size_t>(a)][static_cast<std::size_t>(h)];
}

// [reference]: the reference instrument and its errors.
void read_reference(StrictTable& r, sim::Scenario& sc) {
  sc.meta.reference = dsp::Reference{r.string("kind", "KGM182"), r.strings("axes")};
  if (r.has("scale_ppm")) {
    const auto v = r.numbers("scale_ppm", 3);
    std::copy(v.begin(), v.end(), sc.reference.scale_ppm);
  }
  read_3x2(r, "interp_nm", sc.reference.interp_nm);
  read_3x2(r, "interp_phase_deg", sc.reference.interp_phase_deg);
  sc.reference.signal_period_um = positive(r, "signal_period_um", sc.reference.signal_period_um);
  sc.reference.resolution_nm = r.number("resolution_nm", sc.reference.resolution_nm);
  r.finish();
}

// A per-axis limit key (0 = none) into dst, times unit, when present.
void read_axis_limits(StrictTable& l, const char* key, double (&dst)[3], double unit) {
  if (!l.has(key)) return;
  const auto v = l.numbers(key, 3);
  for (int i = 0; i < 3; ++i) {
    if (v[static_cast<std::size_t>(i)] < 0.0) l.fail(key, "limits must not be negative (0 = none)");
    dst[i] = v[static_cast<std::size_t>(i)] * unit;
  }
}

// [limits]: the interpolator's limits.
void read_limits(StrictTable& l, sim::Scenario& sc) {
  sc.limits.a_max_mm_s2 = positive(l, "a_max_mps2", sc.limits.a_max_mm_s2 / 1000.0) * 1000.0;
  sc.limits.j_max_mm_s3 = positive(l, "jerk_mps3", sc.limits.j_max_mm_s3 / 1000.0) * 1000.0;
  sc.limits.rapid_mm_min = positive(l, "rapid_mm_min", sc.limits.rapid_mm_min);
  read_axis_limits(l, "axis_v_mm_min", sc.limits.axis_v_mm_min, 1.0);
  read_axis_limits(l, "axis_a_mps2", sc.limits.axis_a_mm_s2, 1000.0);
  read_axis_limits(l, "axis_jerk_mps3", sc.limits.axis_j_mm_s3, 1000.0);
  l.finish();
}

// [servo.x|y|z]: each axis' position loop.
void read_servo(StrictTable& servo, sim::Scenario& sc) {
  for (int a = 0; a < 3; ++a) {
    const char name[2] = {static_cast<char>('x' + a), 0};
    if (auto t = servo.optional_table(name)) {
      sc.machine.servo[a].kv_per_s = positive(*t, "kv_per_s", 30.0);
      sc.machine.servo[a].feedforward = t->number("feedforward", 0.0);
      sc.machine.servo[a].velocity_tau_s = t->number("velocity_tau_ms", 0.0) * 1e-3;
      t->finish();
    }
  }
  servo.finish();
}

// [effects.*]: every effect the simulator knows, each table (or array of tables) of it.
void read_effects(StrictTable& effects, sim::Scenario& sc) {
  for (const std::string& name : effects.keys()) {
    const std::optional<Effect> e = dsp::model::effect_named(name);
    if (!e) {
      std::string list;
      for (const auto& k : sim::effect_names()) list += (list.empty() ? "" : ", ") + k;
      effects.fail(name, "unknown effect (known: " + list + ")");
    }
    for (StrictTable& t : effects.table_or_tables(name)) read_effect(*e, std::move(t), sc);
    sc.effects_present.push_back(name);
  }
  effects.finish();
}

}  // namespace

sim::Scenario read_scenario_file(const std::string& path, sim::gcode::Dialect gcode_dialect) {
  const toml::table doc = StrictTable::parse_file(path);
  StrictTable root(doc, path, "");
  sim::Scenario sc;
  read_header(root, sc);
  read_told(root, sc);
  if (auto t = root.optional_table("mems")) read_mems(*t, sc);
  if (root.has("sensors_present"))
    sim::set_sensors_present(sc, root.choice("sensors_present", {"both", "head", "table"}, "both"));
  if (auto truth = root.optional_table("truth")) read_truth(*truth, sc);
  read_motion(root, path, gcode_dialect, sc);
  default_run_id(sc);
  read_psd_strips(root, sc);
  sc.meta.reference.reset();
  if (auto r = root.optional_table("reference")) read_reference(*r, sc);
  if (auto l = root.optional_table("limits")) read_limits(*l, sc);
  if (auto servo = root.optional_table("servo")) read_servo(*servo, sc);
  if (auto effects = root.optional_table("effects")) read_effects(*effects, sc);
  // Effects listed under `background` are in the data at tolerance level, not injected.
  if (root.has("background")) sc.effects_background = root.strings("background");
  std::erase_if(sc.effects_present, [&](const std::string& e) {
    return std::find(sc.effects_background.begin(), sc.effects_background.end(), e) != sc.effects_background.end();
  });
  root.finish();
  return sc;
}

}  // namespace eical::drivers
