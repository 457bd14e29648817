#include "tools/explain/extended_model.hpp"

#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/model/effects.hpp"
#include "dsp/model/extension.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace eical::tools::explain {

namespace {

using Params = std::map<std::string, double>;
using dsp::model::Effect;

// The sensor side: what explain took into the model (it made the pipeline follow the
// reference better) as a sensor calibration; the rest stays a finding.
void sensor_calibration(const dsp::RunMeta& meta, const dsp::model::RunExplanation& ex, ExtendedModel& m) {
  auto& cal = m.calibration;
  cal.method = "explain";
  cal.run_id = meta.id;
  for (int s = 0; s < 2; ++s) cal.sensors[s] = meta.sensors[s];
  std::vector<dsp::model::ExplainedEffect> taken;
  for (const auto& x : ex.effects)
    if (x.taken_into_model) taken.push_back(x);
  const dsp::model::Extension ext = dsp::model::extend_sensors(meta, taken);
  for (int s = 0; s < 2; ++s) cal.sensors[s] = ext.sensors[s];
  if (ext.delay_changed) cal.daq_group_delay_samples = ext.daq_group_delay_samples;
  if (ext.skew_changed) cal.daq_skew_head_samples = ext.daq_skew_head_samples;
  m.notes = ext.notes;
}

std::string backlash_toml(const Params& p) {
  std::string o;
  for (const auto& [k, v] : p)
    if (k.rfind("backlash_", 0) == 0)
      o += "\n[[effects.\"machine.backlash\"]]\naxis = \"" + std::string(1, k[9]) +
           "\"\nvalue_um = " + drivers::toml_number(std::abs(v)) + "\n";
  return o;
}

std::string reversal_spike_toml(const Params& p) {
  std::string o;
  for (const auto& [k, v] : p)
    if (k.rfind("spike_", 0) == 0) {
      const auto tau = k.find("tau_");
      const double tau_ms = tau == std::string::npos ? 15.0 : std::atof(k.c_str() + tau + 4);
      o += "\n[[effects.\"machine.reversal_spike\"]]\naxis = \"" + std::string(1, k[6]) +
           "\"\namp_um = " + drivers::toml_number(std::abs(v)) + "\ntau_ms = " + drivers::toml_number(tau_ms) + "\n";
    }
  return o;
}

std::string squareness_toml(const Params& p) {
  std::string o;
  for (const auto& [k, v] : p) {
    int i = 0, j = 0;
    if (!dsp::two_axes(k, "squareness_", i, j)) continue;
    const char* plane = (i == 0 && j == 1) ? "xy" : (i == 1 && j == 2) ? "yz" : "zx";
    o += "\n[[effects.\"machine.squareness\"]]\nplane = \"" + std::string(plane) +
         "\"\nvalue_urad = " + drivers::toml_number(v) + "\n";
  }
  return o;
}

std::string scale_mismatch_toml(const Params& p) {
  std::string o;
  for (const auto& [k, v] : p)
    if (k.rfind("scale_", 0) == 0)
      o += "\n[[effects.\"machine.scale_mismatch\"]]\naxis = \"" + std::string(1, k[6]) +
           "\"\nvalue_ppm = " + drivers::toml_number(v) + "\n";
  return o;
}

// Each axis' sine and cosine terms as one amplitude and phase.
std::string cyclic_error_toml(const Params& p) {
  std::string o;
  for (const auto& [k, v] : p) {
    if (k.rfind("cyclic_", 0) != 0 || k.find("_sin_um") == std::string::npos) continue;
    const std::string base = k.substr(0, k.size() - 7);
    const auto c = p.find(base + "_cos_um");
    const double cs = c == p.end() ? 0.0 : c->second;
    const auto pos = base.find("pitch_");
    const double pitch = pos == std::string::npos ? 10.0 : std::atof(base.c_str() + pos + 6);
    o += "\n[[effects.\"machine.cyclic_error\"]]\naxis = \"" + std::string(1, k[7]) +
         "\"\namp_um = " + drivers::toml_number(std::hypot(v, cs)) + "\npitch_mm = " + drivers::toml_number(pitch) +
         "\nphase_deg = " + drivers::toml_number(std::atan2(cs, v) * 180.0 / std::numbers::pi) + "\n";
  }
  return o;
}

// The simulator's mode: m'' + 2ζω m' + ω² m = −gain (d·a_drive) along d, so the response
// of axis i to input j is gain d_i d_j; explain reports the strongest |G|.
std::string resonance_toml(const dsp::Run& run, const Params& p, std::vector<std::string>& notes) {
  std::string modes;
  for (int k = 0; p.count("mode" + std::to_string(k) + "_frequency_hz"); ++k) {
    const std::string pre = "mode" + std::to_string(k) + "_";
    Eigen::Vector3d d(p.at(pre + "direction_x"), p.at(pre + "direction_y"), p.at(pre + "direction_z"));
    if (!(d.norm() > 0.0)) continue;
    d.normalize();
    const double in = d.cwiseAbs().maxCoeff();
    modes += "\n[[effects.\"machine.resonance\".modes]]\nfrequency_hz = " +
             drivers::toml_number(p.at(pre + "frequency_hz")) +
             "\ndamping_ratio = " + drivers::toml_number(p.at(pre + "damping_ratio")) +
             "\ngain = " + drivers::toml_number(p.at(pre + "gain") / (in * in)) + "\ndirection = [" +
             drivers::toml_number(d.x()) + ", " + drivers::toml_number(d.y()) + ", " + drivers::toml_number(d.z()) +
             "]\n";
  }
  if (run.meta.program.kind == dsp::ProgramKind::freeform && run.meta.program.gcode.empty())
    notes.push_back(
        "machine.resonance: into the scenario; the run's program (a recorded set-point, no G-code) has no "
        "generator: add a [sweep] or a gcode_file to simulate it");
  if (modes.empty()) return "";
  return std::string("\n[effects.\"machine.resonance\"]\npart = \"") + (run.meta.sensor_present[1] ? "head" : "table") +
         "\"\n" + modes;
}

// The significant machine effects as the scenario's [effects] tables; what has no table
// in the simulator stays a note.
std::string machine_effects_toml(const dsp::Run& run, const dsp::model::RunExplanation& ex,
                                 std::vector<std::string>& notes) {
  std::string effects_toml;
  for (const auto& x : ex.effects) {
    if (!x.significant) continue;
    const auto& p = x.params;
    const std::optional<Effect> id = dsp::model::effect_named(x.name);
    if (!id) {  // other.*: no table in the simulator
      notes.push_back(x.name + ": found; not taken into the scenario (its shape is not one of the simulator's tables)");
      continue;
    }
    if (dsp::model::info(*id).side != dsp::model::EffectSide::machine) continue;  // into the calibration
    switch (*id) {
      case Effect::machine_backlash: effects_toml += backlash_toml(p); break;
      case Effect::machine_reversal_spike: effects_toml += reversal_spike_toml(p); break;
      case Effect::machine_squareness: effects_toml += squareness_toml(p); break;
      case Effect::machine_scale_mismatch: effects_toml += scale_mismatch_toml(p); break;
      case Effect::machine_cyclic_error: effects_toml += cyclic_error_toml(p); break;
      case Effect::machine_differential_vibration:
      case Effect::machine_resonance:
        // A driven mode of the head against the table is the simulator's resonance of the
        // moving part: the same equation of motion.
        if (*id == Effect::machine_resonance || p.count("mode0_frequency_hz")) {
          effects_toml += resonance_toml(run, p, notes);
          break;
        }
        [[fallthrough]];
      default:
        notes.push_back(x.name +
                        ": found; not taken into the scenario (its shape is not one of the simulator's tables)");
    }
    notes.push_back(x.name + ": into the scenario");
  }
  return effects_toml;
}

// The axes' lags as position loops (feed-forward assumed 99 %).
std::string servo_toml(const dsp::model::RunExplanation& ex) {
  std::string o;
  for (const auto& x : ex.effects)
    if (dsp::model::effect_named(x.name) == Effect::machine_servo_mismatch)
      for (const auto& [k, v] : x.params)
        if (k.rfind("lag_", 0) == 0 && v > 1e-4)
          o += "\n[servo." + std::string(1, k[4]) + "]\nkv_per_s = " + drivers::toml_number(0.01 / (v * 1e-3)) +
               "\nfeedforward = 0.99\n";
  return o;
}

// The truth: the extended sensors and DAQ ([truth.*]).
std::string truth_tables(const drivers::SensorCalibration& cal, const dsp::RunMeta& meta) {
  std::string truth_toml =
      "\n[truth.daq]\ngroup_delay_samples = " +
      drivers::toml_number(cal.daq_group_delay_samples.value_or(meta.acquisition.daq_group_delay_samples)) +
      "\nskew_head_samples = " +
      drivers::toml_number(cal.daq_skew_head_samples.value_or(meta.acquisition.daq_skew_head_samples)) + "\n";
  for (int s = 0; s < 2; ++s) {
    std::string sec = drivers::sensor_section_toml(s == 0 ? "table" : "head", cal.sensors[s]);
    sec.replace(sec.find("[sensors."), 9, "[truth.sensors.");
    truth_toml += sec;
  }
  return truth_toml;
}

// What eical is told: the run's own run.toml as a scenario (its name, no creation time).
std::string told_tables(const dsp::RunMeta& meta) {
  std::string text = drivers::run_toml_text(meta);
  const auto eol = text.find('\n');
  // A run of one sensor is simulated with that sensor only (the other's columns empty).
  const std::string present = meta.sensor_present[0] && meta.sensor_present[1] ? ""
                              : meta.sensor_present[1]                         ? "\nsensors_present = \"head\""
                                                                               : "\nsensors_present = \"table\"";
  text = "format = \"eical-scenario/1\"\nname = \"explained-" + meta.id +
         "\"\ndescription = \"what eical explain found in " + meta.id + "\"" + present + text.substr(eol);
  if (const auto c = text.find("\ncreated = "); c != std::string::npos) text.erase(c, text.find('\n', c + 1) - c);
  return text;
}

}  // namespace

ExtendedModel extended_model(const dsp::Run& run, const dsp::model::RunExplanation& explanation) {
  ExtendedModel m;
  sensor_calibration(run.meta, explanation, m);
  const std::string effects_toml = machine_effects_toml(run, explanation, m.notes);
  // The scenario: what eical is told = the run's own data sheet, the truth = the extended
  // sensors and DAQ ([truth.*]): simulated, it shows what the recorded run showed.
  m.scenario_toml =
      "# Written by eical explain: the run's program with the effects it found; eical simulate --scenario this-file -o "
      "RUN\n" +
      told_tables(run.meta) + servo_toml(explanation) + effects_toml + truth_tables(m.calibration, run.meta);
  return m;
}

void write_extended_model(const ExtendedModel& model, const std::filesystem::path& calibration_file,
                          const std::filesystem::path& scenario_file) {
  drivers::write_sensor_calibration(model.calibration, calibration_file);
  drivers::write_text_atomic(scenario_file, model.scenario_toml);
}

}  // namespace eical::tools::explain
