// Stage 0: the run's residuals against the nominal model, each axis' loop and the machine
// effects' columns with their shapes chosen on this run.
#include "dsp/core/float_limits.hpp"
#include "dsp/model/explain/stages.hpp"

#include "dsp/pipeline/integration_support.hpp"

#include <cmath>

namespace eical::dsp::model::stage {

ExplainState prepare(const Run& run, const ExplainOptions& options) {
  ExplainState st{run, options, build_residuals(run), {}, {}, {}, {}, {}, {}, {}, true, {}};
  const RunResiduals& rr = st.rr;
  st.ex.run_id = rr.run_id, st.ex.reference = rr.reference;
  // A reference instrument holds the integration as a standstill does.
  st.integration_supported =
      unsupported_integration(rr.measurement).empty() || rr.has_ref[0] || rr.has_ref[1] || rr.has_ref[2];
  if (!st.integration_supported) {
    st.ex.position_not_compared = unsupported_integration(rr.measurement);
    st.ex.nominal_residual_rms_um = st.ex.final_residual_rms_um = kNaN;
    st.ex.heldout_nominal_rms_um = st.ex.heldout_final_rms_um = kNaN;
  }
  // Shapes (spike time constant, cyclic pitch) are chosen on the residual that shows
  // machine effects: reference minus set-point, else the pipeline against the set-point.
  Eigen::MatrixXd hint = Eigen::MatrixXd::Constant(rr.n, 3, kNaN);
  for (const Channel* hc : {&rr.pipeline, &rr.machine})
    for (Eigen::Index i = 0; i < hc->rows(); ++i)
      if (hc == &rr.machine ||
          rr.axis_reference[static_cast<std::size_t>(hc->axis[static_cast<std::size_t>(i)])] == "cmd")
        hint(hc->sample[static_cast<std::size_t>(i)], hc->axis[static_cast<std::size_t>(i)]) = hc->residual_um[i];
  st.lag = common_lag_columns(rr, loop_time_constant_s(rr, hint));
  st.machine = machine_effects(rr, without_lag(hint, st.lag), st.lag);
  for (int a = 0; a < 3; ++a)
    st.cmd_axes[static_cast<std::size_t>(a)] = rr.axis_reference[static_cast<std::size_t>(a)] == "cmd" && rr.moving[a];
  return st;
}

}  // namespace eical::dsp::model::stage
