// Stage: stick-slip while an axis creeps.
#include "dsp/model/explain/stages.hpp"
#include "dsp/model/stick_slip_bursts.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace eical::dsp::model::stage {

namespace {

// Static friction that makes an axis stick-slip while it creeps also holds it at each
// reversal, where it creeps through zero speed: the slide lags until it breaks free, a
// lag after the reversal no larger than the slips' sawtooth. That is the reference's
// reversal-spike column on the stick-slip axis (issue 34: named beside stick-slip on 4 of 5
// seeds, 1.2–1.5 µm against a sawtooth of 2.3–3.0 µm, where the simulated machine had no
// spike). Such a lag is the stick-slip's, not a second effect; one larger than the
// sawtooth, or one on another axis, stays a reversal spike.
void breakaway_within_sawtooth(ExplainState& st, const StickSlipFinding& ss) {
  ExplainedEffect* spike = st.find(name(Effect::machine_reversal_spike));
  if (!spike || !spike->significant || ss.axis < 0 || !(ss.slip_um > 0.0)) return;
  const std::string on_axis = "spike_" + axis_letter(ss.axis) + "_";
  double on = 0.0, elsewhere = 0.0;  // the largest spike on the stick-slip axis and on the others
  for (const auto& [param, value] : spike->params) {
    double& largest = param.rfind(on_axis, 0) == 0 ? on : elsewhere;
    largest = std::max(largest, std::abs(value));
  }
  if (on > ss.slip_um || elsewhere > spike->tolerance) return;
  spike->significant = false, spike->importance_um = 0.0;
  spike->evidence +=
      "; the lag after each reversal on " + axis_letter(ss.axis) +
      fmt(" (%.2f um) lies within the stick-slip's sawtooth (%.2f um): the slide breaking free, ", on, ss.slip_um) +
      "machine.stick_slip";
}

}  // namespace

void test_stick_slip(ExplainState& st) {
  RunResiduals& rr = st.rr;
  std::vector<ExplainedEffect>& all = st.effects;
  // Stick-slip: trains of slips while an axis creeps.
  {
    const StickSlipFinding ss = stick_slip_test(rr);
    ExplainedEffect x;
    x.name = "machine.stick_slip", x.channel = "acceleration", x.unit = "bursts per creep zone", x.tolerance = 8.0;
    x.magnitude = ss.bursts_per_zone, x.significant = ss.found;
    x.params["bursts_in_creep"] = ss.bursts_in_creep, x.params["bursts_elsewhere"] = ss.bursts_elsewhere,
    x.params["creep_zones"] = ss.creep_zones;
    if (ss.slip_um > 0.0) x.params["slip_um"] = ss.slip_um;
    if (ss.axis >= 0) x.params[std::string("axis_") + "xyz"[ss.axis]] = 1.0;
    x.importance_um = ss.found ? std::max(ss.slip_um, 1.0) : 0.0;
    x.bic_drop = ss.bursts_in_creep;
    x.evidence = ss.evidence;
    all.push_back(x);
    st.stick_slip = ss;
  }
}

void breakaway_at_reversals(ExplainState& st) {
  if (st.stick_slip.found) breakaway_within_sawtooth(st, st.stick_slip);
}

}  // namespace eical::dsp::model::stage
