#include "sim/effects.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/model/effects.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace eical::sim {
namespace {

bool differs(double a, double b) { return std::abs(a - b) > 1e-12 * std::max(1.0, std::abs(b)); }
bool differs(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm() > 1e-12; }

}  // namespace

const std::vector<std::string>& effect_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& e : dsp::model::effect_catalogue()) out.emplace_back(e.name);
    return out;
  }();
  return names;
}

std::vector<std::string> effects_in(const Scenario& scenario) {
  using dsp::model::Effect;
  std::array<bool, dsp::model::kEffectCount> on{};
  auto add = [&](Effect e, bool cond) { on[static_cast<std::size_t>(e)] = on[static_cast<std::size_t>(e)] || cond; };
  for (int s = 0; s < 2; ++s) {
    const SensorTruth& t = scenario.truth[s];
    const dsp::SensorSpec& n = scenario.meta.sensors[s];
    add(Effect::sensor_scale, differs(t.spec.k1_v_per_g, n.k1_v_per_g));
    add(Effect::sensor_bias_drift,
        t.bias_rw_ug_per_rts != 0.0 || t.bias_step_ug != 0.0 || t.bias_drift_ug_per_s != 0.0);
    add(Effect::sensor_nonlinearity,
        differs(t.spec.k2_g_per_g2, n.k2_g_per_g2) || differs(t.spec.k3_g_per_g3, n.k3_g_per_g3));
    add(Effect::sensor_cross_coupling,
        t.k_cross_g_per_g.squaredNorm() > 0.0 || t.k_cross2_g_per_g2.squaredNorm() > 0.0);
    add(Effect::sensor_misalignment, (t.spec.to_machine - n.to_machine).norm() > 1e-12);
    add(Effect::sensor_dynamics, differs(t.spec.f0_hz, n.f0_hz) || differs(t.spec.zeta, n.zeta));
    add(Effect::sensor_damping_amplitude, t.zeta_per_g != n.zeta_per_g);
    add(Effect::sensor_scale_temperature,
        t.temperature.rise_c != 0.0 && (t.spec.tc_k1_ppm_per_c != 0.0 || t.spec.tc_bias_ug_per_c != 0.0));
  }
  add(Effect::daq_group_delay,
      differs(scenario.daq.group_delay_samples, scenario.meta.acquisition.daq_group_delay_samples) ||
          scenario.daq.skew_head_samples != scenario.meta.acquisition.daq_skew_head_samples);
  add(Effect::site_coriolis, scenario.coriolis);
  add(Effect::machine_common_vibration, scenario.common_vibration.on());
  add(Effect::machine_differential_vibration,
      scenario.differential_vibration.gain.squaredNorm() > 0.0 || !scenario.differential_tones.empty());
  add(Effect::machine_resonance, scenario.resonance.on());
  const MachineErrors& m = scenario.machine;
  for (int i = 0; i < 3; ++i) {
    add(Effect::machine_backlash, m.backlash_um[i] != 0.0);
    add(Effect::machine_reversal_spike, m.spike[i].amp_um != 0.0);
    add(Effect::machine_squareness, m.squareness_urad[i] != 0.0);
    add(Effect::machine_scale_mismatch, m.scale_ppm[i] != 0.0);
    add(Effect::machine_cyclic_error, m.cyclic[i].amp_um != 0.0);
    add(Effect::machine_straightness, m.straightness[i].direction >= 0 && m.straightness[i].bow_um != 0.0);
    add(Effect::machine_stick_slip, m.stick_slip[i].amp_um != 0.0);
  }
  // Servo mismatch: the lags (1 − ff)/Kv of the axes differ.
  double lag_min = kInf, lag_max = -kInf;
  for (int i = 0; i < 3; ++i) {
    const double lag = m.servo[i].kv_per_s > 0.0 ? (1.0 - m.servo[i].feedforward) / m.servo[i].kv_per_s : 0.0;
    lag_min = std::min(lag_min, lag), lag_max = std::max(lag_max, lag);
  }
  add(Effect::machine_servo_mismatch, lag_max - lag_min > 1e-9);
  std::vector<std::string> ordered;  // in the table's order
  for (const auto& e : dsp::model::effect_catalogue())
    if (on[static_cast<std::size_t>(e.id)]) ordered.emplace_back(e.name);
  return ordered;
}

EffectLists effect_lists(const Scenario& scenario) {
  EffectLists l;
  const std::vector<std::string> found = effects_in(scenario);
  if (scenario.effects_present.empty() && scenario.effects_background.empty()) {
    l.present = found;
    return l;
  }
  l.present = scenario.effects_present;
  for (const auto& e : found)
    if (std::find(l.present.begin(), l.present.end(), e) == l.present.end()) l.background.push_back(e);
  return l;
}

}  // namespace eical::sim
