#include "sim/truth.hpp"

#include "dsp/model/effects.hpp"
#include "sim/effects.hpp"
#include "sim/sensor/earth_rate.hpp"

#include <Eigen/LU>

#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

namespace eical::sim {
namespace {

using dsp::model::Effect;

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  std::string s = buf;
  if (s == "inf" || s == "-inf" || s == "nan") return s;
  // TOML floats need a decimal point or exponent.
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string vec3(const Eigen::Vector3d& v) { return "[" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + "]"; }
std::string arr(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}
std::string mat3(const Eigen::Matrix3d& m) {
  std::string s = "[";
  for (int r = 0; r < 3; ++r) s += (r ? ", " : "") + vec3(m.row(r).transpose());
  return s + "]";
}
std::string str(const std::string& s) { return "\"" + s + "\""; }
std::string list(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + str(v[k]);
  return s + "]";
}

const char* const kAxis[3] = {"x", "y", "z"};
const char* const kPair[3] = {"xy", "yz", "zx"};
const char* const kSensor[2] = {"table", "head"};

// Small rotation (mrad) about the sensor axes between nominal and true mounting.
Eigen::Vector3d misalignment_mrad(const Eigen::Matrix3d& nominal, const Eigen::Matrix3d& truth) {
  const Eigen::Matrix3d r = nominal.inverse() * truth;
  return 1e3 * Eigen::Vector3d(0.5 * (r(2, 1) - r(1, 2)), 0.5 * (r(0, 2) - r(2, 0)), 0.5 * (r(1, 0) - r(0, 1)));
}

// What a mounting that is no small rotation is: "rotation" (proper: two signs flipped, or
// two axes exchanged with one sign), "mirror" (improper: one sign flipped, two axes swapped).
const char* mounting_kind(const Eigen::Matrix3d& nominal, const Eigen::Matrix3d& truth) {
  return (nominal.inverse() * truth).determinant() > 0.0 ? "rotation" : "mirror";
}

// Which sensors an effect shows in.
std::string sensors_with(const Scenario& sc, bool (*pred)(const Scenario&, int)) {
  const bool t = pred(sc, 0), h = pred(sc, 1);
  return t && h ? "both" : (t ? "table" : (h ? "head" : "none"));
}

// Which sensors an effect of the sensor.* family shows in: its test on one sensor.
using SensorTest = bool (*)(const Scenario&, int);

SensorTest sensor_test(Effect e) {
  switch (e) {
    case Effect::sensor_scale:
      return [](const Scenario& s, int i) {
        return (s.truth[i].spec.k1_v_per_g - s.meta.sensors[i].k1_v_per_g).norm() > 1e-12;
      };
    case Effect::sensor_bias_drift:
      return [](const Scenario& s, int i) {
        return s.truth[i].bias_rw_ug_per_rts != 0.0 || s.truth[i].bias_step_ug != 0.0 ||
               s.truth[i].bias_drift_ug_per_s != 0.0;
      };
    case Effect::sensor_nonlinearity:
      return [](const Scenario& s, int i) {
        return (s.truth[i].spec.k2_g_per_g2 - s.meta.sensors[i].k2_g_per_g2).norm() +
                   (s.truth[i].spec.k3_g_per_g3 - s.meta.sensors[i].k3_g_per_g3).norm() >
               1e-12;
      };
    case Effect::sensor_cross_coupling:
      return [](const Scenario& s, int i) {
        return s.truth[i].k_cross_g_per_g.squaredNorm() + s.truth[i].k_cross2_g_per_g2.squaredNorm() > 0.0;
      };
    case Effect::sensor_misalignment:
      return [](const Scenario& s, int i) {
        return (s.truth[i].spec.to_machine - s.meta.sensors[i].to_machine).norm() > 1e-12;
      };
    case Effect::sensor_dynamics:
      return [](const Scenario& s, int i) {
        return std::abs(s.truth[i].spec.f0_hz - s.meta.sensors[i].f0_hz) +
                   std::abs(s.truth[i].spec.zeta - s.meta.sensors[i].zeta) >
               1e-12;
      };
    case Effect::sensor_damping_amplitude:
      return [](const Scenario& s, int i) { return s.truth[i].zeta_per_g != s.meta.sensors[i].zeta_per_g; };
    case Effect::sensor_scale_temperature:
      return [](const Scenario& s, int i) { return s.truth[i].temperature.rise_c != 0.0; };
    default: return nullptr;
  }
}

// The parameters of a sensor effect in sensor s.
std::string sensor_effect_params(const Scenario& sc, Effect e, int s) {
  const SensorTruth& t = sc.truth[s];
  switch (e) {
    case Effect::sensor_scale: return "k1_v_per_g = " + vec3(t.spec.k1_v_per_g) + "\n";
    case Effect::sensor_bias_drift:
      return "rw_ug_per_rts = " + num(t.bias_rw_ug_per_rts) + "\nstep_ug = " + num(t.bias_step_ug) +
             "\ndrift_ug_per_s = " + num(t.bias_drift_ug_per_s) + "\n";
    case Effect::sensor_nonlinearity:
      return "k2_g_per_g2 = " + vec3(t.spec.k2_g_per_g2) + "\nk3_g_per_g3 = " + vec3(t.spec.k3_g_per_g3) + "\n";
    case Effect::sensor_cross_coupling:
      return "k_cross_g_per_g = " + mat3(t.k_cross_g_per_g) + "\nk_cross2_g_per_g2 = " + mat3(t.k_cross2_g_per_g2) +
             "\n";
    case Effect::sensor_misalignment: {
      std::string o;
      // A sign flip, swap or mirror is no small rotation: the true matrix says what it is.
      if (!t.axes_map.empty())
        o += "axes_map = " + str(t.axes_map) +
             "\nmounting = " + str(mounting_kind(sc.meta.sensors[s].to_machine, t.spec.to_machine)) + "\n";
      else
        o += "misalignment_mrad = " + vec3(misalignment_mrad(sc.meta.sensors[s].to_machine, t.spec.to_machine)) + "\n";
      return o + "to_machine = " + mat3(t.spec.to_machine) + "\n";
    }
    case Effect::sensor_dynamics: return "f0_hz = " + num(t.spec.f0_hz) + "\nzeta = " + num(t.spec.zeta) + "\n";
    case Effect::sensor_damping_amplitude:
      return "zeta0 = " + num(t.spec.zeta) + "\nzeta_per_g = " + num(t.zeta_per_g) + "\n";
    case Effect::sensor_scale_temperature:
      return "rise_c = " + num(t.temperature.rise_c) + "\ntau_s = " + num(t.temperature.tau_s) +
             "\ntc_k1_ppm_per_c = " + num(t.spec.tc_k1_ppm_per_c) +
             "\ntc_bias_ug_per_c = " + num(t.spec.tc_bias_ug_per_c) + "\n";
    default: return "";
  }
}

// A sensor effect: the sensors it shows in, and its parameters in the head when only the
// head has it, else in the table.
std::string sensor_effect_table(const Scenario& sc, Effect e) {
  const SensorTest pred = sensor_test(e);
  const std::string which = pred ? sensors_with(sc, pred) : "none";
  return "sensor = " + str(which) + "\n" + sensor_effect_params(sc, e, which == "head" ? 1 : 0);
}

std::string tones_table(const std::string& name, const std::vector<Tone>& tones) {
  std::string o;
  for (const Tone& t : tones)
    o += "\n[[effects.\"" + name + "\".tones]]\nfreq_hz = " + num(t.freq_hz) + "\namp_mg = " + vec3(t.amp_mg) +
         "\nphase_deg = " + num(t.phase_deg) + "\n";
  return o;
}

std::string vibration_effect_table(const Scenario& sc, Effect e) {
  const std::string name(dsp::model::name(e));
  std::string o;
  if (e == Effect::machine_common_vibration) {
    const CommonVibration& v = sc.common_vibration;
    o += "broadband_rms_mg = " + vec3(v.broadband_rms_mg) + "\nband_hz = " + arr(v.band_hz, 2) + "\n";
    o += tones_table(name, v.tones);
    o += "\n[effects.\"" + name + "\".mode]\nfreq_hz = " + num(v.mode.freq_hz) + "\nzeta = " + num(v.mode.zeta) +
         "\ngain = " + vec3(v.mode.gain) + "\n";
  } else {
    const DriveMode& d = sc.differential_vibration;
    o += "freq_hz = " + num(d.freq_hz) + "\nzeta = " + num(d.zeta) + "\ngain = " + vec3(d.gain) + "\n";
    o += tones_table(name, sc.differential_tones);
  }
  return o;
}

// "axis = …" and the parameters of the axis with the largest size (the others may carry
// the same effect at background level); nothing when no axis has it.
template <class Size, class Body>
std::string largest_axis(Size size, Body body) {
  int best = -1;
  for (int i = 0; i < 3; ++i)
    if (size(i) != 0.0 && (best < 0 || std::abs(size(i)) > std::abs(size(best)))) best = i;
  return best >= 0 ? "axis = " + str(kAxis[best]) + "\n" + body(best) : std::string();
}

// The errors of the axes and between them (machine.*, vibration aside).
std::string machine_effect_table(const Scenario& sc, Effect e) {
  const std::string name(dsp::model::name(e));
  const MachineErrors& m = sc.machine;
  std::string o;
  if (e == Effect::machine_backlash) {
    o += largest_axis([&](int i) { return m.backlash_um[i]; },
                      [&](int i) { return "value_um = " + num(m.backlash_um[i]) + "\n"; });
  } else if (e == Effect::machine_reversal_spike) {
    o += largest_axis(
        [&](int i) { return m.spike[i].amp_um; },
        [&](int i) { return "amp_um = " + num(m.spike[i].amp_um) + "\ntau_ms = " + num(m.spike[i].tau_ms) + "\n"; });
  } else if (e == Effect::machine_servo_mismatch) {
    for (int i = 0; i < 3; ++i)
      o += std::string("lag_") + kAxis[i] +
           "_ms = " + num(m.servo[i].kv_per_s > 0 ? 1e3 * (1.0 - m.servo[i].feedforward) / m.servo[i].kv_per_s : 0.0) +
           "\n";
  } else if (e == Effect::machine_squareness) {
    for (int i = 0; i < 3; ++i)
      if (m.squareness_urad[i] != 0.0)
        o += std::string("plane = ") + str(kPair[i]) + "\nvalue_urad = " + num(m.squareness_urad[i]) + "\n";
  } else if (e == Effect::machine_scale_mismatch) {
    for (int i = 0; i < 3; ++i) o += std::string(kAxis[i]) + "_ppm = " + num(m.scale_ppm[i]) + "\n";
  } else if (e == Effect::machine_cyclic_error) {
    o += largest_axis([&](int i) { return m.cyclic[i].amp_um; },
                      [&](int i) {
                        return "amp_um = " + num(m.cyclic[i].amp_um) + "\npitch_mm = " + num(m.cyclic[i].pitch_mm) +
                               "\nphase_deg = " + num(m.cyclic[i].phase_deg) + "\n";
                      });
  } else if (e == Effect::machine_straightness) {
    o += largest_axis([&](int i) { return m.straightness[i].direction >= 0 ? m.straightness[i].bow_um : 0.0; },
                      [&](int i) {
                        return "direction = " + str(kAxis[m.straightness[i].direction]) +
                               "\nbow_um = " + num(m.straightness[i].bow_um) +
                               "\nspan_mm = " + arr(m.straightness[i].span_mm, 2) + "\n";
                      });
  } else if (e == Effect::machine_resonance) {
    o += "part = " + str(kSensor[sc.resonance.part]) + "\n";
    for (const StructuralMode& md : sc.resonance.modes)
      o += "\n[[effects.\"" + name + "\".modes]]\nfrequency_hz = " + num(md.frequency_hz) +
           "\ndamping_ratio = " + num(md.damping_ratio) + "\ngain = " + num(md.gain) +
           "\ndirection = " + vec3(md.direction.normalized()) + "\n";
  } else if (e == Effect::machine_stick_slip) {
    o += largest_axis([&](int i) { return m.stick_slip[i].amp_um; },
                      [&](int i) {
                        return "amp_um = " + num(m.stick_slip[i].amp_um) +
                               "\nbelow_mm_min = " + num(m.stick_slip[i].below_mm_min) +
                               "\nslip_ms = " + num(m.stick_slip[i].slip_ms) + "\n";
                      });
  }
  return o;
}

// [effects."NAME"]: where an effect present is, with its true parameters.
std::string effect_table(const Scenario& sc, const std::string& name) {
  std::string o = "\n[effects.\"" + name + "\"]\n";
  const std::optional<Effect> e = dsp::model::effect_named(name);
  if (!e) return o;
  switch (dsp::model::info(*e).side) {
    case dsp::model::EffectSide::sensor: return o + sensor_effect_table(sc, *e);
    case dsp::model::EffectSide::daq:
      return o + "group_delay_samples = " + num(sc.daq.group_delay_samples) +
             "\nskew_head_samples = " + num(sc.daq.skew_head_samples) + "\n";
    case dsp::model::EffectSide::site:
      return o + "latitude_deg = " + num(sc.meta.site.latitude_deg) +
             "\nheading_deg = " + num(sc.meta.site.heading_deg) + "\n";
    case dsp::model::EffectSide::machine: break;
  }
  if (*e == Effect::machine_common_vibration || *e == Effect::machine_differential_vibration)
    return o + vibration_effect_table(sc, *e);
  return o + machine_effect_table(sc, *e);
}

// The comments, the scenario, the effects present and in the background, and where each
// present one is.
std::string header_and_effects(const Scenario& sc) {
  const EffectLists effects = effect_lists(sc);
  std::string o;
  o += "# truth.toml -- synthetic run, true parameters (eical sim 2).\n";
  o += "# [effects] present: injected on purpose; background: also in the data, at tolerance level.\n";
  o += "# Noise densities are two-sided (sample std = n sqrt(fs), sigma_x = n T^1.5/sqrt(3)).\n";
  o += "# [sensors.*].to_machine is the true mounting; machine errors in relative-position sense.\n";
  o += "generator = \"eical-sim 2\"\n";
  o += "scenario = " + str(sc.name) + "\nseed = " + std::to_string(sc.seed) + "\ndescription = " + str(sc.description) +
       "\n";
  o += std::string("sensors_present = ") +
       (sc.meta.sensor_present[0] && sc.meta.sensor_present[1]
            ? "\"both\""
            : (sc.meta.sensor_present[1] ? "\"head\"" : "\"table\"")) +
       "\n";
  o += "\n[effects]\npresent = " + list(effects.present) + "\nbackground = " + list(effects.background) + "\n";
  for (const auto& e : effects.present) o += effect_table(sc, e);
  return o;
}

// [sensors.table] or [sensors.head]: the true sensor and its case temperature.
std::string sensor_section(const Scenario& sc, int s, double duration_s) {
  const SensorTruth& st = sc.truth[s];
  const auto& t = st.spec;
  std::string o;
  o += std::string("\n[sensors.") + kSensor[s] + "]\n";
  o += "model = " + str(t.model) + "\nto_machine = " + mat3(t.to_machine) + "\n";
  o += "k1_v_per_g = " + vec3(t.k1_v_per_g) + "\nk2_g_per_g2 = " + vec3(t.k2_g_per_g2) +
       "\nk3_g_per_g3 = " + vec3(t.k3_g_per_g3) + "\n";
  o += "bias_g = " + vec3(t.bias_g) + "\ntc_k1_ppm_per_c = " + num(t.tc_k1_ppm_per_c) +
       "\ntc_bias_ug_per_c = " + num(t.tc_bias_ug_per_c) + "\n";
  o += "f0_hz = " + num(t.f0_hz) + "\nzeta = " + num(t.zeta) +
       "\nnoise_ug_per_rthz = " + num(sc.noise ? t.noise_ug_per_rthz : 0.0) + "\n";
  o += "temp_ref_c = " + num(t.temp_ref_c) + "\n";
  o += "k_cross_g_per_g = " + mat3(st.k_cross_g_per_g) + "\nk_cross2_g_per_g2 = " + mat3(st.k_cross2_g_per_g2) + "\n";
  if (st.axes_map.empty())
    o += "misalignment_mrad = " + vec3(misalignment_mrad(sc.meta.sensors[s].to_machine, t.to_machine)) + "\n";
  else
    o += "axes_map = " + str(st.axes_map) + "\n";
  o += "zeta_per_g = " + num(st.zeta_per_g) + "\nbias_rw_ug_per_rts = " + num(st.bias_rw_ug_per_rts) +
       "\nbias_step_ug = " + num(st.bias_step_ug) + "\nbias_drift_ug_per_s = " + num(st.bias_drift_ug_per_s) + "\n";
  o += std::string("\n[sensors.") + kSensor[s] + ".temperature]\nt0_c = " + num(st.temperature.t0_c) +
       "\nrise_c = " + num(st.temperature.rise_c) + "\ntau_s = " + num(st.temperature.tau_s) +
       "\nstart_c = " + num(st.temperature.at(0.0)) + "\nend_c = " + num(st.temperature.at(duration_s)) + "\n";
  return o;
}

// [machine_errors.TABLE] with one value per axis.
template <class Get>
std::string axes_table(const char* table, Get get) {
  std::string o = std::string("\n[machine_errors.") + table + "]\n";
  for (int i = 0; i < 3; ++i) o += std::string(kAxis[i]) + " = " + num(get(i)) + "\n";
  return o;
}

// [machine_errors]: the position loops, then each error per axis.
std::string machine_errors_section(const MachineErrors& m) {
  std::string o;
  o += "\n[machine_errors]\n# relative-position sense; an axis' errors are carried by the part that moves it\n";
  o += axes_table("kv_per_s", [&](int i) { return m.servo[i].kv_per_s; });
  o += axes_table("feedforward", [&](int i) { return m.servo[i].feedforward; });
  o += axes_table("velocity_tau_ms", [&](int i) { return m.servo[i].velocity_tau_s * 1e3; });
  o += axes_table("servo_lag_ms", [&](int i) {
    return m.servo[i].kv_per_s > 0 ? 1e3 * (1.0 - m.servo[i].feedforward) / m.servo[i].kv_per_s : 0.0;
  });
  o += axes_table("backlash_um", [&](int i) { return m.backlash_um[i]; });
  o += axes_table("scale_ppm", [&](int i) { return m.scale_ppm[i]; });
  o += "\n[machine_errors.squareness_urad]\n";
  for (int i = 0; i < 3; ++i) o += std::string(kPair[i]) + " = " + num(m.squareness_urad[i]) + "\n";
  for (int i = 0; i < 3; ++i) {
    o += std::string("\n[machine_errors.reversal_spike.") + kAxis[i] + "]\namp_um = " + num(m.spike[i].amp_um) +
         "\ntau_ms = " + num(m.spike[i].tau_ms) + "\n";
    o += std::string("\n[machine_errors.cyclic.") + kAxis[i] + "]\namp_um = " + num(m.cyclic[i].amp_um) +
         "\npitch_mm = " + num(m.cyclic[i].pitch_mm) + "\nphase_deg = " + num(m.cyclic[i].phase_deg) + "\n";
    if (m.straightness[i].direction >= 0)
      o += std::string("\n[machine_errors.straightness.") + kAxis[i] +
           "]\ndirection = " + str(kAxis[m.straightness[i].direction]) + "\nbow_um = " + num(m.straightness[i].bow_um) +
           "\nspan_mm = " + arr(m.straightness[i].span_mm, 2) + "\n";
    o += std::string("\n[machine_errors.stick_slip.") + kAxis[i] + "]\namp_um = " + num(m.stick_slip[i].amp_um) +
         "\nbelow_mm_min = " + num(m.stick_slip[i].below_mm_min) + "\nslip_ms = " + num(m.stick_slip[i].slip_ms) + "\n";
  }
  return o;
}

// [daq] and [site].
std::string daq_and_site_sections(const Scenario& sc) {
  std::string o;
  o += "\n[daq]\nanti_alias_filter = " + std::string(sc.daq.anti_alias_filter ? "true" : "false") +
       "\ngroup_delay_samples = " + num(sc.daq.group_delay_samples) +
       "\nskew_head_samples = " + num(sc.daq.skew_head_samples) + "\n";
  o += "offset_counts = [";
  for (int c = 0; c < 6; ++c) o += (c ? ", " : "") + std::to_string(sc.daq.offset_counts[c]);
  o += "]\nnoise_nv_per_rthz = " + num(sc.daq.noise_nv_per_rthz) + "\noversample = " + std::to_string(sc.oversample) +
       "\n";
  o += "\n[site]\nlatitude_deg = " + num(sc.meta.site.latitude_deg) +
       "\nheading_deg = " + num(sc.meta.site.heading_deg) + "\ng_mps2 = " + num(sc.meta.site.g_mps2) +
       "\ncoriolis = " + (sc.coriolis ? "true" : "false") +
       "\nomega_machine_radps = " + vec3(earth_rate_machine(sc.meta.site)) + "\n";
  return o;
}

// [nc]: the limits, when each move runs and each trigger comes; [nc.sweep] for a sweep.
std::string nc_section(const Scenario& sc, const nc::SetPoint& tr) {
  std::string o;
  o += "\n[nc]\na_max_mps2 = " + num(sc.limits.a_max_mm_s2 / 1000.0) +
       "\njerk_mps3 = " + num(sc.limits.j_max_mm_s3 / 1000.0) + "\nmoves_s = [";
  const auto spans = tr.move_spans_s();
  for (std::size_t k = 0; k < spans.size(); ++k)
    o += (k ? ", [" : "[") + num(spans[k].first) + ", " + num(spans[k].second) + "]";
  o += "]\ntriggers = [";
  for (std::size_t k = 0; k < tr.triggers().size(); ++k)
    o += (k ? ", [" : "[") + num(tr.triggers()[k].t_s) + ", " + std::to_string(tr.triggers()[k].code) + "]";
  o += "]\n";
  if (sc.sweep.on) {
    const nc::KlipperTest& k = sc.sweep.test;
    o += "\n[nc.sweep]\n# Klipper's resonance test (sim/nc/klipper_excitation)\nfreq_start_hz = " +
         num(k.freq_start_hz) + "\nfreq_end_hz = " + num(k.freq_end_hz) + "\naccel_per_hz = " + num(k.accel_per_hz) +
         "\nhz_per_sec = " + num(k.hz_per_sec) + "\nsweeping_accel_mm_s2 = " + num(k.sweeping_accel_mm_s2) +
         "\nsweeping_period_s = " + num(k.sweeping_period_s) + "\nlegacy = " + (k.legacy_moves ? "true" : "false") +
         "\nstop_accel_mm_s2 = " + num(k.stop_accel_mm_s2) + "\ndirection = " + vec3(sc.sweep.direction.normalized()) +
         "\nstart_mm = " + vec3(sc.sweep.start_mm) + "\nlead_in_s = " + num(sc.sweep.lead_in_s) +
         "\ntail_s = " + num(sc.sweep.tail_s) + "\n";
  }
  return o;
}

// [[machine_errors.resonance]], [vibration.common] and [vibration.differential] with their tones.
std::string modes_and_vibration_sections(const Scenario& sc) {
  std::string o;
  for (const StructuralMode& md : sc.resonance.modes)
    o += "\n[[machine_errors.resonance]]\npart = " + str(kSensor[sc.resonance.part]) +
         "\nfrequency_hz = " + num(md.frequency_hz) + "\ndamping_ratio = " + num(md.damping_ratio) +
         "\ngain = " + num(md.gain) + "\ndirection = " + vec3(md.direction.normalized()) + "\n";
  const CommonVibration& v = sc.common_vibration;
  o += "\n[vibration.common]\nbroadband_rms_mg = " + vec3(v.broadband_rms_mg) + "\nband_hz = " + arr(v.band_hz, 2) +
       "\nmode_freq_hz = " + num(v.mode.freq_hz) + "\nmode_zeta = " + num(v.mode.zeta) +
       "\nmode_gain = " + vec3(v.mode.gain) + "\n";
  for (const Tone& t : v.tones)
    o += "\n[[vibration.common.tones]]\nfreq_hz = " + num(t.freq_hz) + "\namp_mg = " + vec3(t.amp_mg) +
         "\nphase_deg = " + num(t.phase_deg) + "\n";
  const DriveMode& d = sc.differential_vibration;
  o += "\n[vibration.differential]\nfreq_hz = " + num(d.freq_hz) + "\nzeta = " + num(d.zeta) +
       "\ngain = " + vec3(d.gain) + "\n";
  for (const Tone& t : sc.differential_tones)
    o += "\n[[vibration.differential.tones]]\nfreq_hz = " + num(t.freq_hz) + "\namp_mg = " + vec3(t.amp_mg) +
         "\nphase_deg = " + num(t.phase_deg) + "\n";
  return o;
}

// [[psd]] per strip and [reference].
std::string psd_and_reference_sections(const Scenario& sc) {
  std::string o;
  for (std::size_t k = 0; k < sc.meta.psd.size(); ++k) {
    const auto& p = sc.meta.psd[k];
    const PsdTruth pt = k < sc.psd.size() ? sc.psd[k] : PsdTruth{};
    o += "\n[[psd]]\nmeasures = " + str(p.measures) + "\ncenter_mm = " + arr(p.center_mm, 2) +
         "\nlength_mm = " + num(p.length_mm) + "\nwidth_mm = " + num(p.width_mm) +
         "\nlockin_tau_s = " + num(p.lockin_tau_s) + "\nspot_mm = " + num(pt.spot_mm) +
         "\nfull_scale_v = " + num(pt.full_scale_v) + "\nnonlinearity = " + num(pt.nonlinearity) +
         "\nnoise_v_per_rthz = " + num(pt.noise_v_per_rthz) + "\n";
  }
  if (sc.meta.reference) {
    const ReferenceTruth& r = sc.reference;
    o += "\n[reference]\nkind = " + str(sc.meta.reference->kind) + "\naxes = " + list(sc.meta.reference->axes) +
         "\nscale_ppm = " + arr(r.scale_ppm, 3) + "\ninterp_nm = [" + arr(r.interp_nm[0], 2) + ", " +
         arr(r.interp_nm[1], 2) + ", " + arr(r.interp_nm[2], 2) + "]" + "\ninterp_phase_deg = [" +
         arr(r.interp_phase_deg[0], 2) + ", " + arr(r.interp_phase_deg[1], 2) + ", " + arr(r.interp_phase_deg[2], 2) +
         "]" + "\nsignal_period_um = " + num(r.signal_period_um) + "\nresolution_nm = " + num(r.resolution_nm) + "\n";
  }
  return o;
}

}  // namespace

std::string truth_toml(const Scenario& scenario, const nc::SetPoint& set_point) {
  std::string o = header_and_effects(scenario);
  for (int s = 0; s < 2; ++s) o += sensor_section(scenario, s, set_point.duration_s());
  o += machine_errors_section(scenario.machine);
  o += daq_and_site_sections(scenario);
  o += nc_section(scenario, set_point);
  o += modes_and_vibration_sections(scenario);
  o += psd_and_reference_sections(scenario);
  return o;
}

}  // namespace eical::sim
