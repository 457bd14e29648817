// Stage 1: the integrated motion against each axis' reference, through the integration's
// noise model (kf_selection.hpp): the sensor effects as parameter groups, the machine
// effects of the axes that have only the set-point, and the servo of those axes as base.
#include "dsp/model/explain/stages.hpp"
#include "dsp/model/kf_selection.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {
namespace {

// Servo mismatch of the set-point-only axes: their base lags, compared.
void servo_mismatch_from_base(ExplainState& st, const KfSelection& ks) {
  std::vector<std::pair<int, std::pair<double, double>>> lags;
  for (int a = 0; a < 3; ++a)
    if (const auto it = ks.base_value.find("servo_lag_" + axis_letter(a) + "_ms"); it != ks.base_value.end())
      lags.push_back({a, {it->second, ks.base_sigma.at(it->first)}});
  if (lags.size() < 2) return;
  ExplainedEffect x = effect_of(Effect::machine_servo_mismatch);
  x.channel = "total";
  double sure = 0.0;
  for (std::size_t i = 0; i < lags.size(); ++i)
    for (std::size_t j = i + 1; j < lags.size(); ++j) {
      const double d = lags[j].second.first - lags[i].second.first,
                   sd = std::hypot(lags[i].second.second, lags[j].second.second);
      x.params["lag_" + axis_letter(lags[j].first) + "_minus_" + axis_letter(lags[i].first) + "_ms"] = d;
      x.magnitude = std::max(x.magnitude, std::abs(d)), sure = std::max(sure, std::abs(d) - 2.0 * sd);
    }
  for (const auto& [a, l] : lags) x.params["lag_" + axis_letter(a) + "_ms"] = l.first;
  x.significant = sure > x.tolerance;
  x.importance_um = x.significant ? x.magnitude * st.rr.v_cmd.cwiseAbs().maxCoeff() : 0.0;
  x.evidence =
      fmt("the axes' servo lags against the set-point (the integrated motion's base model) differ by %.3g ms (%.3g at "
          "2 sigma) against a tolerance of %.3g ms",
          x.magnitude, sure, x.tolerance);
  st.merge(std::move(x));
}

// What a machine group's fit says as its effect: parameters fitted per axis averaged, the size.
Attribution machine_attribution(const EffectModel& m, const std::map<std::string, double>& value) {
  Attribution a;
  a.name = m.name, a.tolerance = m.tolerance, a.unit = m.unit, a.regressor = m.regressor;
  Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.params.size()));
  for (std::size_t p = 0; p < m.params.size(); ++p)
    if (const auto mean = axes_mean(value, m.params[p]))
      full[static_cast<Eigen::Index>(p)] = *mean, a.params[m.params[p]] = *mean;
  a.magnitude = m.magnitude(full);
  return a;
}

// The effects one group's verdict stands for, at its fitted values and 2σ towards and away
// from zero.
bool attributions(const ExplainState& st, const GroupVerdict& v, bool is_sensor, std::vector<Attribution>& atts,
                  std::vector<Attribution>& sure, std::vector<Attribution>& far) {
  const std::map<std::string, double> sure_value = toward_zero(v.value, v.sigma),
                                      far_value = away_from_zero(v.value, v.sigma);
  if (is_sensor) {
    atts = attribute_sensor_group(st.rr, v.name, v.value);
    sure = attribute_sensor_group(st.rr, v.name, sure_value);
    far = attribute_sensor_group(st.rr, v.name, far_value);
    return true;
  }
  const auto it =
      std::find_if(st.machine.begin(), st.machine.end(), [&](const EffectModel& e) { return e.name == v.name; });
  if (it == st.machine.end()) return false;
  atts = {machine_attribution(*it, v.value)};
  sure = {machine_attribution(*it, sure_value)};
  far = {machine_attribution(*it, far_value)};
  return true;
}

// The magnitude of the attribution named `name` (0: none).
double magnitude_named(const std::vector<Attribution>& atts, const std::string& name) {
  for (const auto& a : atts)
    if (a.name == name) return a.magnitude;
  return 0.0;
}

// One attributed effect of a group's verdict.
ExplainedEffect explained(const ExplainState& st, const GroupVerdict& v, bool is_sensor, const Attribution& at,
                          double sure_magnitude, double far_magnitude, double share) {
  ExplainedEffect x;
  x.name = at.name, x.params = at.params, x.magnitude = at.magnitude, x.tolerance = at.tolerance, x.unit = at.unit;
  x.sigma = magnitude_sigma(at.magnitude, sure_magnitude, far_magnitude);
  x.group = v.name, x.resembles = at.regressor;
  if (v.accepted) x.params["model_group_accepted"] = 1.0;  // its values are part of the fitted model
  x.channel = is_sensor ? st.rr.reference : "total";
  x.bic_drop = v.bic_drop;
  x.residual_rms_before_um = v.fit_rms_before_um, x.residual_rms_after_um = v.fit_rms_after_um;
  x.heldout_rms_before_um = v.held_rms_before_um, x.heldout_rms_after_um = v.held_rms_after_um;
  x.importance_um = std::max(0.0, v.held_rms_before_um - v.held_rms_after_um) * share;
  x.significant = v.accepted && sure_magnitude > x.tolerance;
  x.evidence =
      "the integrated motion against the " + st.rr.reference + " follows " + at.regressor + " (model group '" + v.name +
      "')" +
      fmt("; BIC drop %.0f; prediction error at the held-out samples %.3f -> %.3f um; size %.3g (%.3g at 2 sigma) ",
          v.bic_drop, v.held_rms_before_um, v.held_rms_after_um, x.magnitude, sure_magnitude) +
      x.unit + fmt(" against a tolerance of %.3g ", x.tolerance) + x.unit;
  if (v.accepted && !x.significant) x.evidence += " (not clearly outside the tolerance: background)";
  // Known from the site, not fitted: named when it matters for the motion and the run
  // agrees with it better than without it.
  if (v.name == "coriolis") {
    x.significant = x.magnitude > x.tolerance && v.loglik_gain > kKnownEffectEvidence;
    x.importance_um = x.significant ? std::max(0.0, v.held_rms_before_um - v.held_rms_after_um) : 0.0;
    x.evidence += fmt("; the run with it is %.1f (2 ln L, effective count) more likely than without", v.loglik_gain);
  }
  return x;
}

}  // namespace

void fit_integrated_motion(ExplainState& st) {
  if (!st.integration_supported) return;  // a double integral nothing holds shows no effect (compare_accelerations)
  const RunResiduals& rr = st.rr;
  std::vector<ParamGroup> groups = sensor_groups(rr);
  const std::size_t n_sensor_groups = groups.size();
  for (const auto& e : st.machine) {
    if (e.name == name(Effect::machine_servo_mismatch))
      continue;  // the servos of set-point-only axes are the base model's
    ParamGroup g = as_group(e, st.cmd_axes);
    if (!g.params.empty()) groups.push_back(std::move(g));
  }
  KfSelectionOptions ko;
  ko.min_bic_drop = st.options.min_bic_drop, ko.min_heldout_gain = st.options.min_heldout_gain;
  ko.known_min_loglik_gain = kKnownEffectEvidence;
  // The nominal model's noise: the data sheet's, without the pipeline's allowance for a bias
  // jump at every move start — a jump between moves is an effect to find (sensor.bias_drift),
  // and so is anything else that acts like one (Earth-rate Coriolis during a long move).
  fusion::ErrorModel noise_model = pipeline_config(rr.meta, 1).fusion;
  noise_model.bias_step_um_s2 = kNominalBiasStepUmS2;
  const KfSelection ks = select_groups_kf(rr.tracks, groups, noise_model, ko, servo_base(rr, st.lag));
  servo_mismatch_from_base(st, ks);
  for (const auto& v : ks.groups) {
    const bool is_sensor = std::any_of(groups.begin(), groups.begin() + static_cast<std::ptrdiff_t>(n_sensor_groups),
                                       [&](const ParamGroup& g) { return g.name == v.name; });
    std::vector<Attribution> atts, sure_atts, far_atts;
    if (!attributions(st, v, is_sensor, atts, sure_atts, far_atts)) continue;
    // One group's gain shared by the effects it stands for, by how far each is outside its band.
    double excess_sum = 0.0;
    for (const auto& at : atts) excess_sum += at.tolerance > 0.0 ? at.magnitude / at.tolerance : 0.0;
    for (const auto& at : atts) {
      const double share =
          atts.size() > 1 && excess_sum > 0.0 && at.tolerance > 0.0 ? at.magnitude / at.tolerance / excess_sum : 1.0;
      st.merge(explained(st, v, is_sensor, at, magnitude_named(sure_atts, at.name), magnitude_named(far_atts, at.name),
                         share));
    }
  }
  st.ex.heldout_nominal_rms_um = ks.held_rms_nominal_um, st.ex.heldout_final_rms_um = ks.held_rms_final_um;
  st.leftover.held_rms_um = ks.held_rms_all_um, st.leftover.held_expected_rms_um = ks.held_expected_rms_all_um;
}

}  // namespace eical::dsp::model::stage
