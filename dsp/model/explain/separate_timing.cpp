// Stage: the sensors' timing against the DAQ delay the PSD strips show.
#include "dsp/core/float_limits.hpp"
#include "dsp/identify/delay_estimate.hpp"
#include "dsp/model/explain/stages.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

namespace {

ExplainedEffect* find_effect(std::vector<ExplainedEffect>& all, const std::string& name) {
  for (auto& e : all)
    if (e.name == name) return &e;
  return nullptr;
}

// daq.group_delay from the PSD readings against the reference.
ExplainedEffect delay_effect(const RunResiduals& rr, const identify::DelayEstimate& de) {
  ExplainedEffect d;
  d.name = "daq.group_delay", d.channel = "psd", d.unit = "samples", d.tolerance = 0.3;
  const double dd = de.samples - rr.delay_samples;
  d.params["group_delay_samples"] = de.samples, d.params["delay_error_samples"] = dd,
  d.params["sigma_samples"] = de.sigma;
  d.magnitude = std::abs(dd);
  d.significant = std::abs(dd) > d.tolerance && std::abs(dd) > 3.0 * de.sigma;
  d.importance_um = std::abs(dd) / rr.fs_hz * rr.v_cmd.cwiseAbs().maxCoeff() * 1000.0 / std::sqrt(2.0);
  d.bic_drop = de.sigma > 0.0 ? (dd / de.sigma) * (dd / de.sigma) : 0.0;
  d.evidence =
      fmt("the PSD readings (through the DAQ filter, not the sensors) lag the reference by %.3f +- %.3f samples "
          "against %.3f nominal",
          de.samples, de.sigma, rr.delay_samples);
  if (de.mounting_assumed) d.evidence += " (strips crossed at one speed: taken where run.toml puts them)";
  return d;
}

// What each sensor's own timing is once the delay is known. Both sensors off by the same:
// their dynamics (2ζ/ω0); the head off against the table: the DAQ's skew between their
// channels (run-format: "table and head channels are skewed in time") — the simpler of two
// explanations only when the DAQ already shows a delay error; else one sensor's own dynamics.
void split_sensor_timing(const RunResiduals& rr, const ExplainOptions& o, const identify::DelayEstimate& de,
                         ExplainedEffect& d, ExplainedEffect& dyn) {
  const double dd = de.samples - rr.delay_samples;
  const double delay_us = -dd * 1e6 / rr.fs_hz;
  double own[2] = {kNaN, kNaN};
  for (int s2 = 0; s2 < 2; ++s2)
    if (auto it = dyn.params.find(std::string("damping_term_error_us_") + (s2 == 0 ? "table" : "head"));
        it != dyn.params.end())
      own[s2] = it->second - delay_us;
  double base = std::isfinite(own[0]) ? own[0] : own[1];
  if (std::isfinite(own[0]) && std::isfinite(own[1])) {
    const double skew = -(own[1] - own[0]) * rr.fs_hz / 1e6;  // head later, samples
    // The DAQ shown off: its delay error beyond the tolerance by two standard errors.
    const bool daq_off = std::abs(dd) > d.tolerance && std::abs(dd) > 2.0 * de.sigma;
    if (!daq_off) {
      // The larger of the two sensors' own timing errors.
      if (std::abs(own[1]) > std::abs(own[0])) base = own[1];
    } else if (std::abs(skew) > 0.3) {
      d.params["skew_head_samples"] = skew;
      d.magnitude = std::max(d.magnitude, std::abs(skew));
      d.significant = dyn.bic_drop > o.min_bic_drop;
      d.evidence += fmt("; the head's channels lag the table's by %.2f samples more", skew);
    }
  }
  dyn.magnitude = std::abs(base);
  dyn.params["damping_term_error_us_after_delay"] = base;
  dyn.significant = dyn.bic_drop > o.min_bic_drop && std::abs(base) > dyn.tolerance;
  dyn.evidence += fmt("; %.1f us of it is the DAQ delay the PSD readings show", delay_us);
}

// Without strips and a reference the two are one shift: name the sensor's.
void merge_into_dynamics(ExplainedEffect& del, ExplainedEffect* dyn) {
  if (del.significant) {
    if (dyn && !dyn->significant) {
      dyn->significant = true, dyn->importance_um = del.importance_um;
      for (const auto& [k, v] : del.params) dyn->params[k] = v;
    }
    del.significant = false;
  }
  del.evidence += " (not separable from 2ζ/ω0 without PSD strips and a reference: reported as sensor.dynamics)";
  if (dyn) dyn->evidence += " (or daq.group_delay: the two shift the path alike without PSD strips and a reference)";
}

}  // namespace

// The timing of the sensors' path: 2ζ/ω0 and the DAQ delay shift it alike. The PSD strips
// pass the DAQ filter but not the sensors' PT2: against the reference they give the delay.
void separate_timing(ExplainState& st) {
  RunResiduals& rr = st.rr;
  std::vector<ExplainedEffect>& all = st.effects;
  const bool has_psd = rr.has_psd[0] || rr.has_psd[1];
  ExplainedEffect* dyn = find_effect(all, "sensor.dynamics");
  ExplainedEffect* del = find_effect(all, "daq.group_delay");
  if (rr.reference == "ref" && has_psd) {
    const identify::DelayEstimate de =
        identify::estimate_delay(rr.measurement, rr.meta, identify::DelayReference::reference);
    if (!de.valid) return;
    ExplainedEffect d = delay_effect(rr, de);
    if (dyn) split_sensor_timing(rr, st.options, de, d, *dyn);
    if (del)
      *del = d;
    else
      all.push_back(d);
  } else if (del) {
    merge_into_dynamics(*del, dyn);
  }
}

}  // namespace eical::dsp::model::stage
