// Stage: the extended model and what it gains.
#include "dsp/model/explain/stages.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {
namespace {

// The machine effects of set-point-only axes (significant, fitted on the "total" channel),
// predicted on a channel's rows.
Eigen::VectorXd machine_prediction(const ExplainState& st, const Channel& ch) {
  const std::vector<EffectModel>& machine = st.machine;
  Eigen::VectorXd pred = Eigen::VectorXd::Zero(ch.rows());
  for (const auto& e : st.effects) {
    if (!e.significant || e.channel != "total") continue;
    const auto it =
        std::find_if(machine.begin(), machine.end(), [&](const EffectModel& m) { return m.name == e.name; });
    if (it == machine.end()) continue;
    Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(it->params.size()));
    for (std::size_t p = 0; p < it->params.size(); ++p)
      if (auto f = e.params.find(it->params[p]); f != e.params.end()) full[static_cast<Eigen::Index>(p)] = f->second;
    const Eigen::MatrixXd cols = columns_on(*it, ch);
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      if (st.cmd_axes[static_cast<std::size_t>(ch.axis[static_cast<std::size_t>(i)])]) pred[i] += cols.row(i).dot(full);
  }
  return pred;
}

// The pipeline's residual with the sensor-side effects `taken` in the model and the
// machine effects of set-point-only axes subtracted.
Channel residual_with(const ExplainState& st, const std::vector<ExplainedEffect>& taken) {
  Channel ch = build_residuals(extended_run(st.run, taken)).pipeline;
  ch.residual_um -= machine_prediction(st, ch);
  return ch;
}

// The significant effects the pipeline compensates from a calibration, most important first.
std::vector<std::size_t> pipeline_side_order(const std::vector<ExplainedEffect>& all) {
  static const char* const kPipelineSide[] = {
      "sensor.scale",    "sensor.misalignment",      "sensor.cross_coupling",    "sensor.nonlinearity",
      "sensor.dynamics", "sensor.damping_amplitude", "sensor.scale_temperature", "daq.group_delay"};
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (all[k].significant && std::any_of(std::begin(kPipelineSide), std::end(kPipelineSide),
                                          [&](const char* n) { return all[k].name == n; }))
      order.push_back(k);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return all[a].importance_um > all[b].importance_um; });
  return order;
}

// A sensor-side extension is taken into the model only when the pipeline with it follows
// the reference better: one at a time, the most important first (a fit can be significant
// and still not transfer to the pipeline). `best`: the RMS to beat; `after_ch`: the
// residual with what was taken. Returns the RMS reached.
double take_sensor_side(ExplainState& st, double best, Channel& after_ch) {
  std::vector<ExplainedEffect>& all = st.effects;
  std::vector<ExplainedEffect> taken;
  for (std::size_t k : pipeline_side_order(all)) {
    std::vector<ExplainedEffect> trial = taken;
    trial.push_back(all[k]);
    Channel ch = residual_with(st, trial);
    const double r = moving_axes_rms(st.rr, offsets_out(ch), ch);
    if (r < best) {
      best = r, after_ch = std::move(ch), taken = std::move(trial);
      all[k].taken_into_model = true;
    } else {
      all[k].evidence +=
          fmt("; not taken into the model: the pipeline with it follows the reference no better (%.3f -> %.3f um)",
              best, r);
    }
  }
  return best;
}

// The residual before and after on the rows both channels share, thinned to about 6000.
RunExplanation::Trace before_after_trace(const RunResiduals& rr, const Eigen::VectorXd& before_v,
                                         const Eigen::VectorXd& after_v, const Channel& after_ch) {
  RunExplanation::Trace tr;
  tr.channel = rr.reference;
  const Eigen::Index rows = std::min(before_v.size(), after_v.size());
  const auto step = static_cast<Eigen::Index>(std::max<Eigen::Index>(1, rows / 6000));
  for (Eigen::Index i = 0; i < rows; i += step) {
    if (rr.pipeline.axis[static_cast<std::size_t>(i)] != after_ch.axis[static_cast<std::size_t>(i)]) continue;
    tr.t_s.push_back(rr.t_s[rr.pipeline.sample[static_cast<std::size_t>(i)]]);
    tr.axis.push_back(rr.pipeline.axis[static_cast<std::size_t>(i)]);
    tr.before_um.push_back(before_v[i]), tr.after_um.push_back(after_v[i]);
  }
  return tr;
}

}  // namespace

// The gain: the pipeline's path against each axis' reference, with the nominal model and
// with the extended one (the significant sensor effects in the sensors, the machine
// effects of set-point-only axes subtracted).
void extend_and_measure(ExplainState& st) {
  if (!st.integration_supported) return;  // no position to gain on
  const RunResiduals& rr = st.rr;
  const Eigen::VectorXd before_v = offsets_out(rr.pipeline);
  st.ex.nominal_residual_rms_um = moving_axes_rms(rr, before_v, rr.pipeline);
  Channel after_ch = rr.pipeline;
  after_ch.residual_um -= machine_prediction(st, after_ch);
  const double best = take_sensor_side(st, moving_axes_rms(rr, offsets_out(after_ch), after_ch), after_ch);
  st.ex.final_residual_rms_um = best;
  st.ex.traces.push_back(before_after_trace(rr, before_v, offsets_out(after_ch), after_ch));
}

}  // namespace eical::dsp::model::stage
