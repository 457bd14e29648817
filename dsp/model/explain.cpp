#include "dsp/model/explain.hpp"

#include "dsp/model/effect_catalog.hpp"
#include "dsp/model/explain/stages.hpp"

#include <cmath>

namespace eical::dsp::model {
namespace {

// Pearson r of the nominal residual of each moving axis with the candidate regressors.
std::vector<RunExplanation::Correlation> regressor_correlations(const RunResiduals& rr) {
  std::vector<RunExplanation::Correlation> out;
  const Eigen::VectorXd resid = stage::offsets_out(rr.pipeline);
  const auto& raw = rr.measurement.raw;
  for (int a = 0; a < 3; ++a) {
    if (!rr.moving[a]) continue;
    std::vector<Eigen::Index> rows;
    for (Eigen::Index i = 0; i < rr.pipeline.rows(); ++i)
      if (rr.pipeline.axis[static_cast<std::size_t>(i)] == a) rows.push_back(i);
    if (rows.size() < 10) continue;
    const auto m = static_cast<Eigen::Index>(rows.size());
    Eigen::VectorXd y(m);
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(m, 10);
    Eigen::VectorXd direction;
    std::vector<int> reversals;
    axis_directions(rr, a, direction, reversals);
    for (Eigen::Index k = 0; k < m; ++k) {
      const int s = rr.pipeline.sample[static_cast<std::size_t>(rows[static_cast<std::size_t>(k)])];
      y[k] = resid[rows[static_cast<std::size_t>(k)]];
      const double acc = rr.a_meas(s, a), vel = rr.v_meas(s, a);
      double cross = 0.0;
      for (int b = 0; b < 3; ++b)
        if (b != a && rr.moving[b]) cross += rr.a_meas(s, b);
      const std::size_t tr = s < static_cast<int>(rr.trace.size()) ? rr.trace[static_cast<std::size_t>(s)] : 0;
      const int other = rr.owner[a] == 1 ? 0 : 1;
      const auto& other_sig = other == 0 ? raw.table_mps2 : raw.head_mps2;
      x(k, 0) = rr.cmd(s, a), x(k, 1) = vel, x(k, 2) = acc, x(k, 3) = std::abs(acc) * vel;
      x(k, 4) = s > 0 ? (acc - rr.a_meas(s - 1, a)) / rr.dt_s : 0.0;
      x(k, 5) = cross, x(k, 6) = 0.5 * (rr.temp_c(s, 0) + rr.temp_c(s, 1)), x(k, 7) = rr.t_s[s];
      x(k, 8) = tr < other_sig.size() ? other_sig[tr][a] : 0.0, x(k, 9) = direction[s];
    }
    static const char* const kNames[10] = {"position",
                                           "velocity",
                                           "acceleration",
                                           "|a|*v",
                                           "jerk",
                                           "other axes' acceleration",
                                           "temperature",
                                           "time",
                                           "the other sensor's signal",
                                           "direction since the last reversal"};
    const Eigen::VectorXd yc = y.array() - y.mean();
    for (int c = 0; c < 10; ++c) {
      const Eigen::VectorXd xc = x.col(c).array() - x.col(c).mean();
      const double d = xc.norm() * yc.norm();
      out.push_back({a, kNames[c], d > 0.0 ? xc.dot(yc) / d : 0.0});
    }
  }
  return out;
}

}  // namespace

// One explanation is a flat list of stages over one state (explain/stages.hpp).
static RunExplanation explain_stages(const Run& run, const ExplainOptions& options, bool check_mounting) {
  stage::ExplainState st = stage::prepare(run, options);
  if (check_mounting)
    if (const auto m = stage::wrong_mounting(st)) {
      Run remounted = run;
      remounted.meta.sensors[static_cast<std::size_t>(m->sensor)].to_machine = m->to_machine;
      RunExplanation ex = explain_stages(remounted, options, false);
      ex.effects.insert(ex.effects.begin(), stage::mounting_effect(*m));
      return ex;
    }
  stage::fit_integrated_motion(st);
  stage::test_vibration(st);   // before the reference: the modes found are in its base model,
  stage::test_stick_slip(st);  // and the stick-slip axis' creep lag
  stage::fit_reference_channel(st);
  stage::breakaway_at_reversals(st);
  stage::separate_timing(st);
  stage::report_earth_rate(st);
  stage::test_standstill_bias(st);
  stage::test_damping_band(st);
  stage::compare_accelerations(st);
  stage::apply_physical_bounds(st);
  stage::extend_and_measure(st);
  stage::report_unexplained(st);
  stage::rank(st);
  st.ex.effects = std::move(st.effects);
  st.ex.correlations = regressor_correlations(st.rr);
  return std::move(st.ex);
}

RunExplanation explain_run(const Run& run, const ExplainOptions& options) { return explain_stages(run, options, true); }

TransferGain transfer_gain(const Run& to, const RunExplanation& from) {
  TransferGain g;
  g.from_run = from.run_id, g.to_run = to.meta.id;
  std::vector<ExplainedEffect> taken;
  for (const auto& e : from.effects)
    if (e.taken_into_model) taken.push_back(e);
  const RunResiduals before = build_residuals(to);
  g.before_um = stage::moving_axes_rms(before, stage::offsets_out(before.pipeline), before.pipeline);
  if (taken.empty()) {
    g.after_um = g.before_um;
    return g;
  }
  const RunResiduals after = build_residuals(stage::extended_run(to, taken));
  g.after_um = stage::moving_axes_rms(after, stage::offsets_out(after.pipeline), after.pipeline);
  return g;
}

}  // namespace eical::dsp::model
