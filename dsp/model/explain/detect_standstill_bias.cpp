// Stage: the bias at the standstills (ch. 8.3.2).
#include "dsp/model/explain/stages.hpp"
#include "dsp/model/standstill_bias.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

void test_standstill_bias(ExplainState& st) {
  RunResiduals& rr = st.rr;
  std::vector<ExplainedEffect>& all = st.effects;
  auto find = [&](std::string_view n) { return st.find(n); };
  // The bias at the standstills (ch. 8.3.2): steps between moves, drift, temperature.
  {
    const StandstillBias sb = standstill_bias(rr);
    const bool temp = sb.pattern == "temperature";
    ExplainedEffect b;
    b.name = temp ? "sensor.scale_temperature" : "sensor.bias_drift", b.channel = "standstills", b.unit = "ug",
    b.tolerance = 1.0;
    b.magnitude = sb.largest_change_ug, b.significant = sb.changed;
    b.bic_drop = sb.chi2 - sb.dof;
    b.params["largest_bias_change_ug"] = sb.largest_change_ug,
    b.params["standstills"] = static_cast<double>(sb.windows.size());
    b.params["standstills_changed"] = sb.changed ? 1.0 : 0.0;
    if (temp) {
      b.params["bias_tc_error_ug_per_c"] = sb.temp_coeff_ug_per_c,
      b.params["temperature_change_c"] = sb.temperature_change_c;
      b.params["bias_tc_of_head"] = sb.temp_coeff_sensor == 1 ? 1.0 : 0.0;
    } else if (sb.pattern == "steps")
      b.params["step_ug"] = sb.step_ug;
    else if (sb.pattern == "drift")
      b.params["drift_ug_per_s"] = sb.drift_ug_per_s;
    // Ranking: the position error the change makes over a quarter-second move, µm.
    b.importance_um = sb.changed ? 0.5 * sb.largest_change_ug * rr.meta.site.g_mps2 * 0.0625 : 0.0;
    b.evidence = sb.evidence;
    if (ExplainedEffect* reg = find(b.name)) {
      reg->evidence += "; " + b.evidence;
      for (const auto& [k, v] : b.params) reg->params[k] = v;
      if (b.significant && !reg->significant)
        reg->importance_um = std::max(reg->importance_um, b.importance_um), reg->channel = "standstills";
      reg->significant = reg->significant || b.significant;
    } else {
      all.push_back(b);
    }
    // One cause for one change: the standstills say whether the bias followed the
    // temperature or the time; the integrated motion's drift group is the same change.
    const char* other = temp ? "sensor.bias_drift" : "sensor.scale_temperature";
    if (ExplainedEffect* oe = find(other);
        oe && oe->significant && sb.changed && (temp || sb.temperature_change_c < 0.05)) {
      oe->significant = false;
      oe->evidence += temp ? " (the drift follows the case temperature: see sensor.scale_temperature)"
                           : " (the case temperature hardly changed: see sensor.bias_drift)";
    }
  }
}

}  // namespace eical::dsp::model::stage
