// Stage: vibration in the spectra and modes the motion drives.
#include "dsp/model/explain/stages.hpp"
#include "dsp/model/structural_modes.hpp"
#include "dsp/model/vibration_spectra.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

namespace {

// With both sensors the relative acceleration is head - table: a mode the motion drives in
// it is the head moving against the table (machine.differential_vibration, run-format.md),
// whichever part carries it; machine.resonance stays the name of a mode one sensor sees
// against the commanded motion, where nothing says the motion is relative. The mode's
// parameters move over with it; its size in µm is the larger of the spectral test's and
// the modes' relative displacement.
void name_as_differential(ExplainedEffect& res, ExplainedEffect& d) {
  double displacement_um = 0.0;
  for (const auto& [key, value] : res.params) {
    d.params[key] = value;
    if (key.size() > 20 && key.compare(key.size() - 20, 20, "_displacement_rms_um") == 0)
      displacement_um = std::max(displacement_um, value);
  }
  d.magnitude = std::max(d.magnitude, displacement_um);
  d.params["displacement_um"] = d.magnitude;
  d.significant = true;
  d.importance_um = std::max(d.importance_um, res.importance_um);
  d.evidence = "driven by the motion, " + res.evidence + (d.evidence.empty() ? "" : "; spectra: " + d.evidence);
  res.significant = false, res.importance_um = 0.0;
  res.evidence =
      "the mode found is the head moving against the table (both sensors): named "
      "machine.differential_vibration";
}

}  // namespace

void test_vibration(ExplainState& st) {
  RunResiduals& rr = st.rr;
  std::vector<ExplainedEffect>& all = st.effects;
  // Vibration.
  {
    const VibrationTests v = vibration_tests(rr);
    ExplainedEffect c, d;
    c.name = "machine.common_vibration", c.channel = "spectrum", c.unit = "mg", c.tolerance = 0.05,
    c.magnitude = v.common.rms_mg;
    c.params["rms_mg"] = v.common.rms_mg, c.params["coherence"] = v.common.coherence;
    for (std::size_t i = 0; i < v.common.lines.size(); ++i)
      c.params["line" + std::to_string(i) + "_hz"] = v.common.lines[i].freq_hz;
    c.significant = v.common.found && v.common.rms_mg > c.tolerance;
    c.importance_um = c.significant ? 1.0 + v.common.rms_mg : 0.0;
    c.evidence = v.common.evidence;
    d.name = "machine.differential_vibration", d.channel = "spectrum", d.unit = "um", d.tolerance = 0.1,
    d.magnitude = v.differential.displacement_um;
    d.params["rms_mg"] = v.differential.rms_mg, d.params["displacement_um"] = v.differential.displacement_um;
    for (std::size_t i = 0; i < v.differential.lines.size(); ++i)
      d.params["line" + std::to_string(i) + "_hz"] = v.differential.lines[i].freq_hz;
    // Relative motion that matters for the position (0.1 µm), or an acceleration ten times
    // the sensors' own noise over the band (0.3 mg RMS) that a light structure shows.
    d.significant =
        v.differential.found && (v.differential.displacement_um > d.tolerance || v.differential.rms_mg > 0.3);
    d.importance_um = d.significant ? v.differential.displacement_um : 0.0;
    d.evidence = v.differential.evidence;
    // Modes the motion drives (machine.resonance, run-format.md): the frequency response of
    // the measured relative acceleration over the commanded one, with one sensor or two. A
    // mode is a property of the machine, named in its unit (amplification at its peak);
    // machine.differential_vibration is the head moving against the table by itself.
    ExplainedEffect res;
    res.name = "machine.resonance", res.channel = "frequency response", res.unit = "amplification", res.tolerance = 0.1;
    // The band comes from the data: the rate (find_structural_modes stops at 0.4·fs) and
    // where the motion drives the response (coherence), never from the sensor's declared
    // corner: a chip declared at 200 Hz would hide a printer's modes above 67 Hz. The
    // sensors' own roll-off is broad (ζ ≈ 0.7) and is no structural mode.
    const ModeSearch ms = find_structural_modes(rr.a_meas, rr.a_cmd, 1.0 / rr.dt_s, rr.moving, kModeMaxHz);
    int k = 0;
    double largest = 0.0;
    for (const auto& md : ms.modes) {
      if (!md.significant) continue;
      st.modes.push_back(md);
      const std::string pre = "mode" + std::to_string(k++) + "_";
      res.params[pre + "frequency_hz"] = md.frequency_hz,
                       res.params[pre + "sigma_frequency_hz"] = md.sigma_frequency_hz;
      res.params[pre + "damping_ratio"] = md.damping_ratio,
                       res.params[pre + "sigma_damping_ratio"] = md.sigma_damping_ratio;
      res.params[pre + "gain"] = md.gain, res.params[pre + "peak_amplification"] = md.peak_amplification;
      for (int a = 0; a < 3; ++a) res.params[pre + "direction_" + "xyz"[a]] = md.direction[static_cast<std::size_t>(a)];
      res.params[pre + "displacement_rms_um"] = md.displacement_rms_um;
      res.evidence += fmt("; a mode at %.2f +- %.2f Hz, damping %.3f +- %.3f, ", md.frequency_hz, md.sigma_frequency_hz,
                          md.damping_ratio, md.sigma_damping_ratio) +
                      fmt("gain %.3f (x%.2f at its peak), driven along ", md.gain, 1.0 + md.peak_amplification) +
                      std::string(1, "xyz"[md.input_axis]) +
                      fmt(", %.2f mg / %.3f um RMS in this run; chi2 drop %.0f against %.0f, coherence %.2f",
                          md.response_rms_mg, md.displacement_rms_um, md.chi2_drop, md.chi2_threshold, md.coherence);
      largest = std::max(largest, md.peak_amplification);
    }
    std::string modes = res.evidence;  // "; a mode at …; a mode at …"
    if (modes.rfind("; ", 0) == 0) modes.erase(0, 2);
    if (k > 0) {
      res.significant = true;
      res.magnitude = largest, res.importance_um = 1.0 + largest;
      res.params["residual_rms_before_mg"] = ms.residual_rms_before_mg,
      res.params["residual_rms_after_mg"] = ms.residual_rms_after_mg;
      res.evidence = (rr.meta.sensor_present[0] && rr.meta.sensor_present[1] ? "head against table: " : "") + modes +
                     "; " + ms.evidence +
                     fmt("; with the modes, measured - commanded acceleration beyond the drive's own response falls "
                         "from %.3g to %.3g mg RMS",
                         ms.residual_rms_before_mg, ms.residual_rms_after_mg);
    } else {
      res.evidence = ms.evidence + ": no mode stands out";
    }
    if (k > 0 && rr.meta.sensor_present[0] && rr.meta.sensor_present[1]) name_as_differential(res, d);
    all.push_back(c), all.push_back(d), all.push_back(res);
  }
}

}  // namespace eical::dsp::model::stage
