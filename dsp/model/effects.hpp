#pragma once
// The effects of run-format.md's table as a type: one catalogue that explain, the
// simulator, the reports and the tests name effects by. Each entry carries its unit, its
// tolerance band (what a data-sheet sensor or a well-kept machine shows anyway: a fit
// inside it is background, not a finding) and its physical bound (what no sensor or
// machine of the kind can have: a fit beyond it is not this effect but something the table
// does not describe, reported as other.residual_like_<group>). docs/explain.md "What the simulation
// gets wrong" prints the table with the reason for each bound.
#include <array>
#include <optional>
#include <string_view>

namespace eical::dsp::model {

enum class Effect {
  sensor_scale,
  sensor_bias_drift,
  sensor_nonlinearity,
  sensor_cross_coupling,
  sensor_misalignment,
  sensor_dynamics,
  sensor_damping_amplitude,
  sensor_scale_temperature,
  daq_group_delay,
  site_coriolis,
  machine_common_vibration,
  machine_differential_vibration,
  machine_backlash,
  machine_reversal_spike,
  machine_servo_mismatch,
  machine_squareness,
  machine_scale_mismatch,
  machine_cyclic_error,
  machine_straightness,
  machine_stick_slip,
  machine_resonance,
};
inline constexpr std::size_t kEffectCount = 21;

// Where the effect lives: what a calibration of the sensors can take into the pipeline
// (sensor, daq, site) and what only the machine's compensation can (machine).
enum class EffectSide { sensor, daq, site, machine };

struct EffectInfo {
  Effect id;
  std::string_view name;  // run-format.md
  std::string_view unit;  // of the size explain reports
  double tolerance;       // background band, in `unit`
  double bound;           // physical bound, in `unit` (servo-class sensors, machine tools)
  double bound_mems;      // the same for MEMS sensors (noise ≥ 20 µg/√Hz)
  EffectSide side;
  bool compensable;  // the pipeline can take it into its model (sensor calibration)
  std::string_view bound_reason;
};

const std::array<EffectInfo, kEffectCount>& effect_catalogue();
const EffectInfo& info(Effect e);
std::string_view name(Effect e);
// The effect of a run-format name (nullopt: not in the table).
std::optional<Effect> effect_named(std::string_view name);

}  // namespace eical::dsp::model
