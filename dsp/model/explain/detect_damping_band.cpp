// Stage: damping that grows with the acceleration, where the shared vibration shows it.
#include "dsp/model/damping_band_regression.hpp"
#include "dsp/model/explain/stages.hpp"

#include <cmath>

namespace eical::dsp::model::stage {

void test_damping_band(ExplainState& st) {
  const DampingBandFinding f = damping_band_test(st.rr);
  if (!f.valid || !f.found) return;  // the reference channel's candidate stands
  ExplainedEffect x = effect_of(Effect::sensor_damping_amplitude);
  x.channel = "acceleration band";
  x.magnitude = f.zeta_per_g, x.sigma = f.sigma_zeta_per_g;
  x.significant = std::abs(f.zeta_per_g) - 2.0 * f.sigma_zeta_per_g > x.tolerance;
  x.bic_drop = f.bic_drop[static_cast<std::size_t>(f.sensor)];
  x.evidence = f.evidence;
  x.resembles = "the vibration both sensors share, left in head - table in step with one sensor's own |a|";
  x.params["sensor"] = f.sensor;
  x.params["sigma_zeta_per_g"] = f.sigma_zeta_per_g;
  x.params["probe_rms_mg"] = f.probe_rms_mg;
  x.params["band_lo_hz"] = f.band_lo_hz, x.params["band_hi_hz"] = f.band_hi_hz;
  // The extension's parameters: k on each moving axis the sensor carries.
  for (int j = 0; j < 3; ++j)
    if (st.rr.moving[static_cast<std::size_t>(j)] && st.rr.owner[static_cast<std::size_t>(j)] == f.sensor)
      x.params["zeta_per_g_" + axis_letter(j)] = f.zeta_per_g;
  // What it does to the path is small (a lag of 2ζ0k|a|/(ω0 g)): it ranks after what moves it.
  x.importance_um = x.significant ? 0.1 : 0.0;
  st.merge(std::move(x));
}

}  // namespace eical::dsp::model::stage
