// Stage: stick-slip while an axis creeps.
#include "dsp/model/explain/stages.hpp"
#include "dsp/model/stick_slip_bursts.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

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
  }
}

}  // namespace eical::dsp::model::stage
