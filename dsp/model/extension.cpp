#include "dsp/model/extension.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/model/effects.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <string>

namespace eical::dsp::model {
namespace {

int owner(const RunMeta& m, int a) { return axis_owner(m.machine, a); }

using Params = std::map<std::string, double>;
// Per sensor (table, head): measured = (I + E) true, machine axes.
using CrossAxisTerms = std::array<Eigen::Matrix3d, 2>;

void add_scale(const RunMeta& meta, const Params& p, CrossAxisTerms& e) {
  for (const auto& [k, v] : p)
    if (k.rfind("scale_", 0) == 0 && k.size() > 6) {
      const int a = axis_index(k[6]);
      if (a >= 0 && owner(meta, a) >= 0) e[owner(meta, a)](a, a) += v * 1e-6;
    }
}

void add_misalignment(const RunMeta& meta, const Params& p, CrossAxisTerms& e) {
  for (const auto& [k, v] : p) {
    int j = 0, i = 0;
    if (two_axes(k, "rotation_", j, i) && owner(meta, j) >= 0) {
      e[owner(meta, j)](i, j) += v * 1e-3, e[owner(meta, j)](j, i) -= v * 1e-3;
    } else if (k.rfind("tilt_", 0) == 0 && k.size() > 12) {
      const int jj = axis_index(k[5]), ii = axis_index(k[12]);
      if (jj >= 0 && ii >= 0 && owner(meta, jj) >= 0) e[owner(meta, jj)](ii, jj) += v * 1e-3;
    }
  }
}

void add_cross_coupling(const RunMeta& meta, const Params& p, CrossAxisTerms& e) {
  for (const auto& [k, v] : p) {
    int i = 0, j = 0;
    if (two_axes(k, "cross_", i, j) && owner(meta, i) >= 0)
      e[owner(meta, i)](i, j) += v * 1e-6, e[owner(meta, i)](j, i) += v * 1e-6;
  }
}

void add_nonlinearity(const RunMeta& meta, const Params& p, Extension& x) {
  for (const auto& [k, v] : p) {
    const int a = k.size() > 3 ? axis_index(k[3]) : -1;
    if (a < 0 || owner(meta, a) < 0) continue;
    auto& sp = x.sensors[owner(meta, a)];
    if (k.rfind("k2_", 0) == 0) sp.k2_g_per_g2[a] += v * 1e-6;
    if (k.rfind("k3_", 0) == 0) sp.k3_g_per_g3[a] += v * 1e-6;
  }
}

void add_dynamics(const Params& p, Extension& x) {
  for (int s = 0; s < 2; ++s) {
    const std::string who = s == 0 ? "table" : "head";
    auto it = p.find("damping_term_error_us_after_delay");
    if (it == p.end()) it = p.find("damping_term_error_us_" + who);
    if (it == p.end()) continue;
    auto& sp = x.sensors[s];
    const double w0 = 2.0 * std::numbers::pi * sp.f0_hz;
    sp.zeta = std::max(0.0, (2.0 * sp.zeta / w0 - it->second * 1e-6) * w0 / 2.0);
  }
  x.notes.push_back("sensor.dynamics: 2ζ/ω0 into ζ (f0 kept)");
}

void add_group_delay(const Params& p, Extension& x) {
  if (auto it = p.find("group_delay_samples"); it != p.end())
    x.daq_group_delay_samples = it->second, x.delay_changed = true;
  if (auto it = p.find("skew_head_samples"); it != p.end() && std::abs(it->second) > 0.3)
    x.daq_skew_head_samples += it->second, x.skew_changed = true;
}

// Per axis fitted; per sensor the mean over the axes it moves (one ζ(|a|) law per sensor).
void add_damping_amplitude(const RunMeta& meta, const ExplainedEffect& ef, Extension& x) {
  double sum[2] = {0.0, 0.0};
  int cnt[2] = {0, 0};
  for (const auto& [k, v] : ef.params)
    if (k.rfind("zeta_per_g_", 0) == 0 && k.size() == 12) {
      const int a = axis_index(k[11]);
      if (a >= 0 && owner(meta, a) >= 0) sum[owner(meta, a)] += v, ++cnt[owner(meta, a)];
    }
  for (int s = 0; s < 2; ++s)  // a sensor whose own axes stay in the band keeps its law
    if (cnt[s] && std::abs(sum[s] / cnt[s]) > ef.tolerance) x.sensors[s].zeta_per_g += sum[s] / cnt[s];
}

// (6-16) with the coefficients the run shows. Head − table is what is measured: the
// bias coefficient (the moving axes' mean) goes to the sensor the standstills name;
// each axis' scale coefficient to the sensor that moves it.
void add_scale_temperature(const RunMeta& meta, const Params& p, Extension& x) {
  const int s = p.count("bias_tc_of_head") && p.at("bias_tc_of_head") < 0.5 ? 0 : 1;
  double bias_sum = 0.0, k1_sum[2] = {0.0, 0.0};
  int bias_n = 0, k1_n[2] = {0, 0};
  for (const auto& [k, v] : p) {
    if (!p.count("model_group_accepted")) break;  // the standstills alone: no coefficient per axis
    if (k.size() == 18 &&
        k.rfind("bias_tc_", 0) == 0) {  // bias_tc_<a>_ug_per_c, of the moving axes (they have a scale term)
      const int a = axis_index(k[8]);
      std::string scale_key = "scale_tc_";
      scale_key.append(1, k[8]).append("_ppm_per_c");
      if (a >= 0 && p.count(scale_key)) bias_sum += v, ++bias_n;
    } else if (k.rfind("scale_tc_", 0) == 0 && k.size() > 9) {
      const int a = axis_index(k[9]);
      if (a >= 0 && owner(meta, a) >= 0) k1_sum[owner(meta, a)] += v, ++k1_n[owner(meta, a)];
    }
  }
  // A coefficient beyond what a sensor can have (900 µg/°C, 500 ppm/°C) has absorbed a
  // drift that only looks like the warming: not taken over.
  constexpr double kMaxBiasTc = 900.0, kMaxScaleTc = 500.0;
  if (bias_n && std::abs(bias_sum / bias_n) <= kMaxBiasTc)
    x.sensors[s].tc_bias_ug_per_c += (s == 1 ? 1.0 : -1.0) * bias_sum / bias_n;
  else if (bias_n)
    x.notes.push_back("sensor.scale_temperature: bias coefficient beyond a sensor's (not taken over)");
  for (int k = 0; k < 2; ++k)
    if (k1_n[k] && std::abs(k1_sum[k] / k1_n[k]) <= kMaxScaleTc) x.sensors[k].tc_k1_ppm_per_c += k1_sum[k] / k1_n[k];
}

// One significant effect into the cross-axis terms or the sensors and DAQ; what the
// pipeline does not take from a calibration into the notes.
void apply_effect(const RunMeta& meta, const ExplainedEffect& ef, CrossAxisTerms& e, Extension& x) {
  const Params& p = ef.params;
  const std::optional<Effect> id = effect_named(ef.name);
  if (!id) return;  // other.*: nothing of the sensors to extend
  switch (*id) {
    case Effect::sensor_scale: return add_scale(meta, p, e);
    case Effect::sensor_misalignment: return add_misalignment(meta, p, e);
    case Effect::sensor_cross_coupling: return add_cross_coupling(meta, p, e);
    case Effect::sensor_nonlinearity: return add_nonlinearity(meta, p, x);
    case Effect::sensor_dynamics: return add_dynamics(p, x);
    case Effect::daq_group_delay: return add_group_delay(p, x);
    case Effect::sensor_damping_amplitude: return add_damping_amplitude(meta, ef, x);
    case Effect::sensor_scale_temperature: return add_scale_temperature(meta, p, x);
    default:
      if (info(*id).side == EffectSide::sensor || info(*id).side == EffectSide::site)
        x.notes.push_back(ef.name + ": found; the pipeline does not compensate it from a calibration (yet)");
  }
}

}  // namespace

Extension extend_sensors(const RunMeta& meta, const std::vector<ExplainedEffect>& effects) {
  Extension x;
  for (int s = 0; s < 2; ++s) x.sensors[s] = meta.sensors[s];
  x.daq_group_delay_samples = meta.acquisition.daq_group_delay_samples;
  x.daq_skew_head_samples = meta.acquisition.daq_skew_head_samples;
  CrossAxisTerms e = {{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()}};
  for (const auto& ef : effects)
    if (ef.significant) apply_effect(meta, ef, e, x);
  // The cross-axis terms into the sensors' to_machine: (I + E)⁻¹ · data sheet.
  for (int s = 0; s < 2; ++s)
    if (e[s].cwiseAbs().maxCoeff() > 0.0)
      x.sensors[s].to_machine = (Eigen::Matrix3d::Identity() + e[s]).inverse() * x.sensors[s].to_machine;
  return x;
}

}  // namespace eical::dsp::model
