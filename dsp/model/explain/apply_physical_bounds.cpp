// Stage: a size no sensor or machine of the kind can have is not that effect
// (run-format.md, effects.hpp): it stands in for something the table does not describe and
// is reported as other.residual_like_<group>, with what it resembles and what it explains.
// And a size the data cannot support is no size: an effect that is not significant and
// whose fitted size, or its 2σ interval, reaches beyond the bound is "not identifiable".
#include "dsp/model/explain/stages.hpp"

#include <cmath>

namespace eical::dsp::model::stage {
namespace {

// MEMS chips: noise of tens of µg/√Hz and more; their bounds are wider (effects.hpp).
constexpr double kMemsNoiseUgRtHz = 20.0;

bool mems(const RunMeta& meta) {
  for (int s = 0; s < 2; ++s)
    if (meta.sensor_present[s] && meta.sensors[s].noise_ug_per_rthz >= kMemsNoiseUgRtHz) return true;
  return false;
}

// A drift the standstills contradict: the fit would move the bias between the first and
// the last standstill by far more than they show.
bool contradicted_by_standstills(const ExplainedEffect& drift, const RunResiduals& rr, double& predicted_ug,
                                 double& shown_ug) {
  const auto change = drift.params.find("largest_bias_change_ug");
  const auto count = drift.params.find("standstills");
  const auto changed = drift.params.find("standstills_changed");
  if (change == drift.params.end() || count == drift.params.end() || count->second < 2.0 || rr.n < 2) return false;
  if (changed != drift.params.end() && changed->second > 0.0) return false;  // the standstills show a change themselves
  predicted_ug = drift.magnitude * (rr.t_s[rr.n - 1] - rr.t_s[0]);
  shown_ug = change->second;
  return predicted_ug > 3.0 * shown_ug + 3.0;
}

// A drift the standstills show themselves: they changed, and by what the fit predicts (within
// a factor of three).
bool shown_at_standstills(const ExplainedEffect& drift, const RunResiduals& rr, double& predicted_ug,
                          double& shown_ug) {
  const auto change = drift.params.find("largest_bias_change_ug");
  const auto changed = drift.params.find("standstills_changed");
  if (change == drift.params.end() || changed == drift.params.end() || changed->second <= 0.0 || rr.n < 2) return false;
  predicted_ug = drift.magnitude * (rr.t_s[rr.n - 1] - rr.t_s[0]);
  shown_ug = change->second;
  return predicted_ug <= 3.0 * shown_ug + 3.0 && shown_ug <= 3.0 * predicted_ug + 3.0;
}

ExplainedEffect outside_table(const ExplainedEffect& x, const std::string& why) {
  ExplainedEffect other = x;
  const std::string group = x.group.empty() ? x.name.substr(x.name.find('.') + 1) : x.group;
  other.name = "other.residual_like_" + group;
  other.taken_into_model = false;
  const double explained = std::max(0.0, x.heldout_rms_before_um - x.heldout_rms_after_um);
  // Named only when what it explains matters for a measurement: a fraction of a micrometre
  // at the held-out points is no finding.
  other.significant = std::max(explained, x.importance_um) >= kMaterialUm;
  other.magnitude = std::max(explained, x.importance_um), other.tolerance = kMaterialUm, other.unit = "um explained";
  other.evidence = "a residual shaped like " + (x.resembles.empty() ? std::string(x.name) : x.resembles) + " but " +
                   why + fmt("; it explains %.3g um RMS at the held-out points", explained);
  return other;
}

const char* kind_of(const EffectInfo& i, bool is_mems) {
  return i.side == EffectSide::machine ? "a machine tool" : is_mems ? "a MEMS sensor" : "a servo accelerometer";
}

// The run leaves the size anywhere from the tolerance band to beyond what the kind can have:
// the fit followed something else (a regressor the motion barely excites, a residual of
// another cause). Its numbers are dropped, not shown as a size (issue 34: 1.1e5 1e-6/g of
// nonlinearity, 24 /g of damping growth and 155 µm of reversal spike came out of runs that
// have none, each rejected by the selection and still printed).
void mark_not_identifiable(ExplainedEffect& x, const EffectInfo& i, double bound, bool is_mems) {
  x.identifiable = false;
  x.params.clear();
  x.evidence = "not identifiable: the run cannot size " + x.name + " — the fit" +
               (x.resembles.empty() ? std::string() : " of " + x.resembles) + fmt(" reaches beyond the %.3g ", bound) +
               x.unit + " " + kind_of(i, is_mems) + " can have (" + std::string(i.bound_reason) + ")";
}

}  // namespace

void apply_physical_bounds(ExplainState& st) {
  const bool is_mems = mems(st.rr.meta);
  std::vector<ExplainedEffect> others;
  for (auto& x : st.effects) {
    const auto id = effect_named(x.name);
    if (!id || !x.significant) continue;
    const EffectInfo& i = info(*id);
    const double bound = is_mems ? i.bound_mems : i.bound;
    std::string why;
    if (x.unit == i.unit && std::abs(x.magnitude) > bound)
      why = fmt("%.3g ", x.magnitude) + x.unit + " (" + kind_of(i, is_mems) + fmt(" has at most %.3g: ", bound) +
            std::string(i.bound_reason) + ")";
    double predicted = 0.0, shown = 0.0;
    if (*id == Effect::sensor_bias_drift && x.unit == i.unit && contradicted_by_standstills(x, st.rr, predicted, shown))
      why = fmt("%.3g ug/s would move the bias by %.0f ug over the run, and its standstills agree to %.1f ug",
                x.magnitude, predicted, shown);
    else if (*id == Effect::sensor_bias_drift && x.unit == i.unit && shown_at_standstills(x, st.rr, predicted, shown)) {
      // The sensor itself shows the bias moving this much at rest: a size observed directly
      // is no impossible size, whatever drives it (a sensor warming faster than its kind).
      x.evidence +=
          fmt("; beyond the %.3g ug/s a sensor of its kind drifts, but its standstills show the bias moving by %.0f ug "
              "(the drift predicts %.0f)",
              bound, shown, predicted);
      why.clear();
    }
    if (why.empty()) continue;
    x.significant = false;
    x.evidence += "; not " + x.name + ": " + why;
    others.push_back(outside_table(x, why));
  }
  for (auto& x : st.effects) {
    const auto id = effect_named(x.name);
    if (!id || x.significant) continue;  // a significant size lies within its bound, outside its band at 2σ
    const EffectInfo& i = info(*id);
    if (x.unit != i.unit) continue;
    const double bound = is_mems ? i.bound_mems : i.bound;
    const double reach = std::abs(x.magnitude) + (std::isfinite(x.sigma) ? 2.0 * x.sigma : 0.0);
    if (reach > bound) mark_not_identifiable(x, i, bound, is_mems);
  }
  for (auto& o : others) st.merge(std::move(o));
}

}  // namespace eical::dsp::model::stage
