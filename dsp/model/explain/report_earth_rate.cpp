// Stage: the Earth rate's Coriolis acceleration, from the site.
#include "dsp/model/explain/stages.hpp"
#include "dsp/pipeline/coriolis.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

void report_earth_rate(ExplainState& st) {
  RunResiduals& rr = st.rr;
  std::vector<ExplainedEffect>& all = st.effects;
  auto find = [&](std::string_view n) { return st.find(n); };
  // Earth rate: known from the site, not fitted (on a circle a common scale error looks the
  // same); its size says whether it matters.
  {
    ExplainedEffect c;
    c.name = "site.coriolis", c.channel = "site", c.unit = "ug", c.tolerance = 1.0;
    const Eigen::Vector3d two_w = 2.0 * earth_rate_machine_radps(rr.meta.site);
    double peak = 0.0;
    for (int s2 = 0; s2 < rr.n; ++s2)
      peak = std::max(peak, two_w.cross(Eigen::Vector3d(rr.v_meas.row(s2).transpose()) * 1e-3).norm());
    c.magnitude = peak / (rr.meta.site.g_mps2 * 1e-6);
    c.params["peak_ug"] = c.magnitude;
    c.evidence =
        fmt("2 w x v of this motion peaks at %.2f ug from the site's latitude and heading; eical analyze --coriolis "
            "corrects it",
            c.magnitude);
    if (ExplainedEffect* fitted = find("site.coriolis")) {
      fitted->evidence += "; " + c.evidence;
      fitted->params["peak_ug"] = c.magnitude;
    } else {
      c.evidence += " (not fitted here: the motion does not separate it from a scale error)";
      all.push_back(c);
    }
  }
}

}  // namespace eical::dsp::model::stage
