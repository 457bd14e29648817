#include "dsp/model/explain.hpp"

#include "dsp/core/error.hpp"
#include "dsp/identify/delay_estimate.hpp"
#include "dsp/model/effect_catalog.hpp"
#include "dsp/model/effect_selection.hpp"
#include "dsp/model/extension.hpp"
#include "dsp/model/kf_selection.hpp"
#include "dsp/model/spectral_tests.hpp"
#include "dsp/model/standstill_bias.hpp"
#include "dsp/model/stick_slip_test.hpp"
#include "dsp/model/structural_modes.hpp"
#include "dsp/pipeline/coriolis.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::dsp::model {
namespace {

// Jackknife blocks of the machine channel: half a second, several per move.
constexpr double kJackknifeBlockS = 0.5;
// What the rest before a move leaves the bias uncertain by (≈ 0.3 µg: the noise over a
// few tenths of a second of rest), µm/s².
constexpr double kNominalBiasStepUmS2 = 3.0;
// A known effect (the Earth rate) is named when the run favours it: 2 ln(likelihood ratio)
// above 2, "positive" evidence on the Kass–Raftery scale.
constexpr double kKnownEffectEvidence = 2.0;
// What an effect outside the table must explain to be named: half the instrument's 1 µm.
constexpr double kMaterialUm = 0.5;
// Structural modes of machine tools lie below this; a response feature above it is the
// sensors' and the DAQ's business.
constexpr double kModeMaxHz = 300.0;

template <typename... Num>
std::string fmt(const char* f, Num... v) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, static_cast<double>(v)...);
  return buf;
}


// An effect's columns on this channel's rows (µm per unit).
Eigen::MatrixXd columns_on(const EffectModel& e, const Channel& ch) {
  Eigen::MatrixXd m(ch.rows(), static_cast<Eigen::Index>(e.columns.size()));
  for (std::size_t p = 0; p < e.columns.size(); ++p)
    for (Eigen::Index i = 0; i < ch.rows(); ++i) m(i, static_cast<Eigen::Index>(p)) = e.columns[p](ch.sample[static_cast<std::size_t>(i)], ch.axis[static_cast<std::size_t>(i)]);
  return m;
}

struct ChannelResult {
  std::vector<ExplainedEffect> effects;
  Eigen::VectorXd before_um, after_um;
  std::vector<bool> heldout;
};

// The base model of reference − set-point, weighted: what every machine has and no effect
// of the table describes — each axis' offset (the reference's zero is arbitrary), the axes'
// common position-loop lag, each axis' acceleration term (its own velocity loop and gain:
// on a circle at one feed this is the same column as a scale mismatch, which that program
// then cannot show), and the rotation of a reference instrument that measures two axes
// against the machine axes ((−θ·y, θ·x): squareness is the symmetric shear of the pair,
// whatever the split in the data).
Eigen::MatrixXd base_columns(const RunResiduals& rr, const Channel& ch, const LagColumns& lag) {
  const Eigen::Index rows = ch.rows();
  std::vector<Eigen::VectorXd> cols;
  auto add = [&](const Eigen::VectorXd& c) {
    if (c.norm() > 0.0) cols.push_back(c);
  };
  for (int a = 0; a < 3; ++a) {
    Eigen::VectorXd offset = Eigen::VectorXd::Zero(rows), acc = Eigen::VectorXd::Zero(rows);
    for (Eigen::Index i = 0; i < rows; ++i)
      if (ch.axis[static_cast<std::size_t>(i)] == a) {
        offset[i] = 1.0 / ch.sigma_um[i];
        acc[i] = lag.acceleration(ch.sample[static_cast<std::size_t>(i)], a) / ch.sigma_um[i];
      }
    add(offset), add(acc);
  }
  Eigen::VectorXd lag_rows(rows);
  for (Eigen::Index i = 0; i < rows; ++i) lag_rows[i] = lag.velocity(ch.sample[static_cast<std::size_t>(i)], ch.axis[static_cast<std::size_t>(i)]) / ch.sigma_um[i];
  add(lag_rows);
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      if (rr.axis_reference[static_cast<std::size_t>(i)] != "ref" || rr.axis_reference[static_cast<std::size_t>(j)] != "ref" || !rr.moving[i] || !rr.moving[j]) continue;
      Eigen::VectorXd c(rows);
      const double mi = rr.cmd.col(i).mean(), mj = rr.cmd.col(j).mean();
      for (Eigen::Index k = 0; k < rows; ++k) {
        const int sm = ch.sample[static_cast<std::size_t>(k)], axk = ch.axis[static_cast<std::size_t>(k)];
        c[k] = (axk == i ? -(rr.cmd(sm, j) - mj) : axk == j ? rr.cmd(sm, i) - mi : 0.0) * 1e-3 / ch.sigma_um[k];
      }
      add(c);
    }
  Eigen::MatrixXd m(rows, static_cast<Eigen::Index>(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) m.col(static_cast<Eigen::Index>(c)) = cols[c];
  return m;
}

ChannelResult analyse_channel(const RunResiduals& rr, const Channel& ch, const std::vector<EffectModel>& catalog, const LagColumns& lag,
                              const ExplainOptions& o) {
  ChannelResult out;
  const Eigen::Index rows = ch.rows();
  const Eigen::MatrixXd nu = base_columns(rr, ch, lag);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(nu);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(rows, nu.cols());
  auto project = [&](const Eigen::MatrixXd& m) { return Eigen::MatrixXd(m - q * (q.transpose() * m)); };
  const Eigen::VectorXd w = ch.sigma_um.cwiseInverse();
  const Eigen::VectorXd y = project(ch.residual_um.cwiseProduct(w));

  std::vector<Candidate> cands;
  std::vector<const EffectModel*> models;
  for (const auto& e : catalog) {
    const Eigen::MatrixXd c = columns_on(e, ch);
    if (c.cwiseAbs().maxCoeff() <= 0.0) continue;  // nothing of it on this channel's axes
    Candidate cand;
    cand.name = e.name;
    cand.regressors = project(w.asDiagonal() * c);
    // A parameter without any footprint here would only make the fit singular.
    std::vector<Eigen::Index> keep;
    for (Eigen::Index p = 0; p < c.cols(); ++p)
      if (cand.regressors.col(p).norm() > 1e-12 * (1.0 + y.norm())) keep.push_back(p);
    if (keep.empty()) continue;
    if (static_cast<Eigen::Index>(keep.size()) < c.cols()) {
      Eigen::MatrixXd r(rows, static_cast<Eigen::Index>(keep.size()));
      for (std::size_t k = 0; k < keep.size(); ++k) r.col(static_cast<Eigen::Index>(k)) = cand.regressors.col(keep[k]);
      cand.regressors = r;
    }
    for (Eigen::Index p : keep) cand.param_names.push_back(e.params[static_cast<std::size_t>(p)]);
    cands.push_back(std::move(cand));
    models.push_back(&e);
  }
  out.heldout.resize(static_cast<std::size_t>(rows));
  for (Eigen::Index i = 0; i < rows; ++i) out.heldout[static_cast<std::size_t>(i)] = rr.heldout[static_cast<std::size_t>(ch.sample[static_cast<std::size_t>(i)])];
  out.before_um = y.cwiseProduct(ch.sigma_um);  // the base model's residual (offsets and common lag out), µm
  out.after_um = out.before_um;
  if (cands.empty() || rows < 50) return out;
  SelectionOptions so;
  so.min_bic_drop = o.min_bic_drop, so.min_heldout_gain = o.min_heldout_gain, so.max_effects = 10;
  so.block.resize(static_cast<std::size_t>(rows));
  for (Eigen::Index i = 0; i < rows; ++i) so.block[static_cast<std::size_t>(i)] = static_cast<int>(rr.t_s[ch.sample[static_cast<std::size_t>(i)]] / kJackknifeBlockS);
  const SelectionResult sel = select_effects(y, cands, out.heldout, so);

  auto split_rms = [&](const Eigen::VectorXd& v, bool held) {
    double s = 0.0;
    std::size_t n = 0;
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (out.heldout[static_cast<std::size_t>(i)] == held) s += v[i] * v[i], ++n;
    return n ? std::sqrt(s / static_cast<double>(n)) : 0.0;
  };
  for (const auto& v : sel.effects) {
    std::size_t k = 0;
    while (k < cands.size() && cands[k].name != v.name) ++k;
    if (k == cands.size()) continue;
    const EffectModel& e = *models[k];
    ExplainedEffect x;
    x.name = v.name, x.channel = ch.name, x.bic_drop = v.bic_drop, x.correlation = v.correlation;
    Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(e.params.size()));
    for (std::size_t p = 0; p < v.param_names.size(); ++p) {
      x.params[v.param_names[p]] = v.params[static_cast<Eigen::Index>(p)];
      for (std::size_t q2 = 0; q2 < e.params.size(); ++q2)
        if (e.params[q2] == v.param_names[p]) full[static_cast<Eigen::Index>(q2)] = v.params[static_cast<Eigen::Index>(p)];
    }
    x.magnitude = e.magnitude(full), x.tolerance = e.tolerance, x.unit = e.unit;
    // Outside the tolerance with confidence: each parameter moved 2σ towards zero.
    Eigen::VectorXd sure = full;
    for (std::size_t p = 0; p < v.param_names.size() && static_cast<Eigen::Index>(p) < v.param_sigma.size(); ++p)
      for (std::size_t q2 = 0; q2 < e.params.size(); ++q2)
        if (e.params[q2] == v.param_names[p]) {
          const double a = full[static_cast<Eigen::Index>(q2)], s2 = 2.0 * v.param_sigma[static_cast<Eigen::Index>(p)];
          sure[static_cast<Eigen::Index>(q2)] = std::abs(a) > s2 ? a - std::copysign(s2, a) : 0.0;
        }
    const double sure_magnitude = e.magnitude(sure);
    // Its own prediction in µm, against the nominal residual (offsets out).
    const Eigen::VectorXd pred = project(w.asDiagonal() * (columns_on(e, ch) * full)).cwiseProduct(ch.sigma_um);
    const Eigen::VectorXd after = out.before_um - pred;
    x.residual_rms_before_um = split_rms(out.before_um, false), x.residual_rms_after_um = split_rms(after, false);
    x.heldout_rms_before_um = split_rms(out.before_um, true), x.heldout_rms_after_um = split_rms(after, true);
    x.importance_um = x.residual_rms_before_um - x.residual_rms_after_um;
    x.significant = v.significant && sure_magnitude > x.tolerance;
    x.evidence = "residual correlates with " + e.regressor + fmt(" (r = %.2f); BIC drop %.0f; held-out RMS %.3f -> %.3f um; ", v.correlation, v.bic_drop,
                                                              x.heldout_rms_before_um, x.heldout_rms_after_um) +
                 fmt("size %.3g (%.3g at 2 sigma) ", x.magnitude, sure_magnitude) + x.unit + fmt(" against a tolerance of %.3g ", x.tolerance) + x.unit;
    if (v.significant && !x.significant) x.evidence += " (not clearly outside the tolerance: background)";
    if (x.significant) out.after_um -= pred;
    out.effects.push_back(std::move(x));
  }
  return out;
}

// A channel's residual with each axis' offset taken out (the reference's zero is arbitrary).
Eigen::VectorXd offsets_out(const Channel& ch) {
  Eigen::VectorXd v = ch.residual_um;
  for (int a = 0; a < 3; ++a) {
    double sum = 0.0;
    int cnt = 0;
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      if (ch.axis[static_cast<std::size_t>(i)] == a) sum += v[i], ++cnt;
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      if (cnt && ch.axis[static_cast<std::size_t>(i)] == a) v[i] -= sum / cnt;
  }
  return v;
}

// RMS over the rows of the axes the program moves.
double moving_axes_rms(const RunResiduals& rr, const Eigen::VectorXd& v, const Channel& ch) {
  double sum = 0.0;
  std::size_t cnt = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (rr.moving[ch.axis[static_cast<std::size_t>(i)]]) sum += v[i] * v[i], ++cnt;
  return cnt ? std::sqrt(sum / static_cast<double>(cnt)) : 0.0;
}

// The run with the sensor-side extensions of `taken` in its meta.
Run extended_run(const Run& run, const std::vector<ExplainedEffect>& taken) {
  const Extension ext = extend_sensors(run.meta, taken);
  Run extended = run;
  for (int s = 0; s < 2; ++s) extended.meta.sensors[s] = ext.sensors[s];
  extended.meta.acquisition.daq_group_delay_samples = ext.daq_group_delay_samples;
  extended.meta.acquisition.daq_skew_head_samples = ext.daq_skew_head_samples;
  return extended;
}

// Pearson r of the nominal residual of each moving axis with the candidate regressors.
std::vector<RunExplanation::Correlation> regressor_correlations(const RunResiduals& rr) {
  std::vector<RunExplanation::Correlation> out;
  const Eigen::VectorXd resid = offsets_out(rr.pipeline);
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
    static const char* kNames[10] = {"position", "velocity", "acceleration", "|a|*v", "jerk", "other axes' acceleration", "temperature", "time",
                                     "the other sensor's signal", "direction since the last reversal"};
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

TransferGain transfer_gain(const Run& to, const RunExplanation& from) {
  TransferGain g;
  g.from_run = from.run_id, g.to_run = to.meta.id;
  std::vector<ExplainedEffect> taken;
  for (const auto& e : from.effects)
    if (e.taken_into_model) taken.push_back(e);
  const RunResiduals before = build_residuals(to);
  g.before_um = moving_axes_rms(before, offsets_out(before.pipeline), before.pipeline);
  if (taken.empty()) {
    g.after_um = g.before_um;
    return g;
  }
  const RunResiduals after = build_residuals(extended_run(to, taken));
  g.after_um = moving_axes_rms(after, offsets_out(after.pipeline), after.pipeline);
  return g;
}

namespace {

void merge(std::vector<ExplainedEffect>& all, ExplainedEffect e) {
  for (auto& a : all) {
    if (a.name != e.name) continue;
    const bool take = (e.significant && !a.significant) || (e.significant == a.significant && e.importance_um > a.importance_um);
    for (const auto& [k, v] : (take ? a : e).params) (take ? e : a).params.emplace(k, v);
    if (take) a = std::move(e);
    return;
  }
  all.push_back(std::move(e));
}

}  // namespace

RunExplanation explain_run(const Run& run, const ExplainOptions& o) {
  RunExplanation ex;
  RunResiduals rr = build_residuals(run);
  ex.run_id = rr.run_id, ex.reference = rr.reference;
  // Shapes (spike time constant, cyclic pitch) are chosen on the residual that shows
  // machine effects: reference minus set-point, else the pipeline against the set-point.
  Eigen::MatrixXd hint = Eigen::MatrixXd::Constant(rr.n, 3, NAN);
  for (const Channel* hc : {&rr.pipeline, &rr.machine})
    for (Eigen::Index i = 0; i < hc->rows(); ++i)
      if (hc == &rr.machine || rr.axis_reference[static_cast<std::size_t>(hc->axis[static_cast<std::size_t>(i)])] == "cmd")
        hint(hc->sample[static_cast<std::size_t>(i)], hc->axis[static_cast<std::size_t>(i)]) = hc->residual_um[i];
  const LagColumns lag = common_lag_columns(rr, loop_time_constant_s(rr, hint));
  const std::vector<EffectModel> machine = machine_effects(rr, without_lag(hint, lag), lag);
  std::vector<ExplainedEffect> all;

  // 1. The integrated motion against each axis' reference, through the integration's noise
  // model: the sensor effects, and the machine effects of axes with the set-point only.
  std::array<bool, 3> cmd_axes{};
  for (int a = 0; a < 3; ++a) cmd_axes[static_cast<std::size_t>(a)] = rr.axis_reference[static_cast<std::size_t>(a)] == "cmd" && rr.moving[a];
  std::vector<ParamGroup> groups = sensor_groups(rr);
  const std::size_t n_sensor_groups = groups.size();
  for (const auto& e : machine) {
    if (e.name == "machine.servo_mismatch") continue;  // the servos of set-point-only axes are the base model's
    ParamGroup g = as_group(e, cmd_axes);
    if (!g.params.empty()) groups.push_back(std::move(g));
  }
  KfSelectionOptions ko;
  ko.min_bic_drop = o.min_bic_drop, ko.min_heldout_gain = o.min_heldout_gain;
  // The nominal model's noise: the data sheet's, without the pipeline's allowance for a bias
  // jump at every move start — a jump between moves is an effect to find (sensor.bias_drift),
  // and so is anything else that acts like one (Earth-rate Coriolis during a long move).
  fusion::ErrorModel noise_model = pipeline_config(rr.meta, 1).fusion;
  noise_model.bias_step_um_s2 = kNominalBiasStepUmS2;
  const std::vector<AxisParam> servo = servo_base(rr, lag);
  const KfSelection ks = select_groups_kf(rr.tracks, groups, noise_model, ko, servo);
  // Servo mismatch of the set-point-only axes: their base lags, compared.
  {
    std::vector<std::pair<int, std::pair<double, double>>> lags;
    for (int a = 0; a < 3; ++a)
      if (const auto it = ks.base_value.find(std::string("servo_lag_") + "xyz"[a] + "_ms"); it != ks.base_value.end())
        lags.push_back({a, {it->second, ks.base_sigma.at(it->first)}});
    if (lags.size() >= 2) {
      ExplainedEffect x;
      x.name = "machine.servo_mismatch", x.channel = "total", x.unit = "ms", x.tolerance = 0.05;
      double sure = 0.0;
      for (std::size_t i = 0; i < lags.size(); ++i)
        for (std::size_t j = i + 1; j < lags.size(); ++j) {
          const double d = lags[j].second.first - lags[i].second.first, sd = std::hypot(lags[i].second.second, lags[j].second.second);
          x.params[std::string("lag_") + "xyz"[lags[j].first] + "_minus_" + "xyz"[lags[i].first] + "_ms"] = d;
          x.magnitude = std::max(x.magnitude, std::abs(d)), sure = std::max(sure, std::abs(d) - 2.0 * sd);
        }
      for (const auto& [a, l] : lags) x.params[std::string("lag_") + "xyz"[a] + "_ms"] = l.first;
      x.significant = sure > x.tolerance;
      x.importance_um = x.significant ? x.magnitude * rr.v_cmd.cwiseAbs().maxCoeff() : 0.0;
      x.evidence = fmt("the axes' servo lags against the set-point (the integrated motion's base model) differ by %.3g ms (%.3g at 2 sigma) against a tolerance of %.3g ms",
                       x.magnitude, sure, x.tolerance);
      merge(all, std::move(x));
    }
  }
  for (const auto& v : ks.groups) {
    const bool is_sensor = std::find_if(groups.begin(), groups.begin() + static_cast<std::ptrdiff_t>(n_sensor_groups),
                                        [&](const ParamGroup& g) { return g.name == v.name; }) != groups.begin() + static_cast<std::ptrdiff_t>(n_sensor_groups);
    // Each value moved 2σ towards zero: the size that is outside the tolerance with confidence.
    std::map<std::string, double> sure_value = v.value;
    for (auto& [k, x] : sure_value)
      if (const auto sg = v.sigma.find(k); sg != v.sigma.end()) x = std::abs(x) > 2.0 * sg->second ? x - std::copysign(2.0 * sg->second, x) : 0.0;
    std::vector<Attribution> atts, sure_atts;
    if (is_sensor) {
      atts = attribute_sensor_group(rr, v.name, v.value);
      sure_atts = attribute_sensor_group(rr, v.name, sure_value);
    } else {
      const auto it = std::find_if(machine.begin(), machine.end(), [&](const EffectModel& e) { return e.name == v.name; });
      if (it == machine.end()) continue;
      Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(it->params.size()));
      Attribution a;
      a.name = it->name, a.tolerance = it->tolerance, a.unit = it->unit, a.regressor = it->regressor;
      for (std::size_t p = 0; p < it->params.size(); ++p) {
        double sum = 0.0;
        int cnt = 0;
        for (const auto& [k, x] : v.value)
          if (k == it->params[p] || k.rfind(it->params[p] + "@", 0) == 0) sum += x, ++cnt;
        full[static_cast<Eigen::Index>(p)] = cnt ? sum / cnt : 0.0;
        if (cnt) a.params[it->params[p]] = full[static_cast<Eigen::Index>(p)];
      }
      a.magnitude = it->magnitude(full);
      atts.push_back(a);
      for (std::size_t p = 0; p < it->params.size(); ++p) {
        double sum = 0.0;
        int cnt = 0;
        for (const auto& [k, x] : sure_value)
          if (k == it->params[p] || k.rfind(it->params[p] + "@", 0) == 0) sum += x, ++cnt;
        full[static_cast<Eigen::Index>(p)] = cnt ? sum / cnt : 0.0;
      }
      a.magnitude = it->magnitude(full);
      sure_atts.push_back(a);
    }
    // One group's gain shared by the effects it stands for, by how far each is outside its band.
    double excess_sum = 0.0;
    for (const auto& at : atts) excess_sum += at.tolerance > 0.0 ? at.magnitude / at.tolerance : 0.0;
    for (const auto& at : atts) {
      ExplainedEffect x;
      x.name = at.name, x.params = at.params, x.magnitude = at.magnitude, x.tolerance = at.tolerance, x.unit = at.unit;
      if (v.accepted) x.params["model_group_accepted"] = 1.0;  // its values are part of the fitted model
      x.channel = is_sensor ? rr.reference : "total";
      x.bic_drop = v.bic_drop;
      x.residual_rms_before_um = v.fit_rms_before_um, x.residual_rms_after_um = v.fit_rms_after_um;
      x.heldout_rms_before_um = v.held_rms_before_um, x.heldout_rms_after_um = v.held_rms_after_um;
      x.importance_um = std::max(0.0, v.held_rms_before_um - v.held_rms_after_um);
      if (atts.size() > 1 && excess_sum > 0.0 && at.tolerance > 0.0) x.importance_um *= at.magnitude / at.tolerance / excess_sum;
      double sure_magnitude = 0.0;
      for (const auto& sa : sure_atts)
        if (sa.name == at.name) sure_magnitude = sa.magnitude;
      x.significant = v.accepted && sure_magnitude > x.tolerance;
      // Known from the site, not fitted: named when it matters for the motion and the run
      // agrees with it at least as well as without it.
      if (v.name == "coriolis") {
        x.significant = x.magnitude > x.tolerance && v.loglik_gain > kKnownEffectEvidence;
        x.importance_um = x.significant ? std::max(0.0, v.held_rms_before_um - v.held_rms_after_um) : 0.0;
        x.evidence += fmt("; the run with it is %.1f (2 ln L, effective count) more likely than without", v.loglik_gain);
      }
      char nums[256];
      std::snprintf(nums, sizeof nums, " (model group '%s'); BIC drop %.0f; prediction error at the held-out samples %.3f -> %.3f um; size %.3g (%.3g at 2 sigma) ",
                    v.name.c_str(), v.bic_drop, v.held_rms_before_um, v.held_rms_after_um, x.magnitude, sure_magnitude);
      x.evidence = "the integrated motion against the " + rr.reference + " follows " + at.regressor + nums + x.unit + fmt(" against a tolerance of %.3g ", x.tolerance) + x.unit;
      if (v.accepted && !x.significant) x.evidence += " (not clearly outside the tolerance: background)";
      if (x.significant && x.magnitude > at.plausible_max) {
        x.significant = false;
        x.evidence += fmt("; larger than a sensor can have (%.3g ", at.plausible_max) + x.unit +
                      "): it stands in for a residual the catalogue does not describe (other.residual_like_" + v.name + ")";
        // Outside the table: the residual has a shape no effect of it explains at a
        // plausible size. Reported with what it resembles and what it explains.
        ExplainedEffect other = x;
        other.name = "other.residual_like_" + v.name;
        // Named only when what it explains matters for a measurement (kMaterialUm at the
        // held-out points): a fraction of a micrometre is not a finding.
        other.significant = std::max(0.0, v.held_rms_before_um - v.held_rms_after_um) >= kMaterialUm, other.taken_into_model = false;
        other.magnitude = x.importance_um, other.tolerance = 0.0, other.unit = "um explained at the held-out points";
        other.evidence = "a residual shaped like " + at.regressor + " but " + fmt("%.3g ", x.magnitude) + x.unit + fmt(" (a sensor has at most %.3g); ", at.plausible_max) +
                     fmt("BIC drop %.0f; prediction error at the held-out samples %.3f -> %.3f um", v.bic_drop, v.held_rms_before_um, v.held_rms_after_um);
        all.push_back(std::move(other));
      }
      merge(all, std::move(x));
    }
  }
  ex.heldout_nominal_rms_um = ks.held_rms_nominal_um, ex.heldout_final_rms_um = ks.held_rms_final_um;

  // 2. Reference minus set-point: the machine effects of axes with a reference.
  ChannelResult machine_fit;
  if (rr.machine.rows() >= 50) {
    machine_fit = analyse_channel(rr, rr.machine, machine, lag, o);
    for (auto& e : machine_fit.effects) merge(all, std::move(e));
  }
  // The timing of the sensors' path: 2ζ/ω0 and the DAQ delay shift it alike. The PSD strips
  // pass the DAQ filter but not the sensors' PT2: against the reference they give the delay.
  const bool has_psd = rr.has_psd[0] || rr.has_psd[1];
  auto find = [&](const std::string& name) -> ExplainedEffect* {
    for (auto& e : all)
      if (e.name == name) return &e;
    return nullptr;
  };
  ExplainedEffect* dyn = find("sensor.dynamics");
  ExplainedEffect* del = find("daq.group_delay");
  if (rr.reference == "ref" && has_psd) {
    const identify::DelayEstimate de = identify::estimate_delay(rr.measurement, rr.meta, identify::DelayReference::reference);
    if (de.valid) {
      ExplainedEffect d;
      d.name = "daq.group_delay", d.channel = "psd", d.unit = "samples", d.tolerance = 0.3;
      const double dd = de.samples - rr.delay_samples;
      d.params["group_delay_samples"] = de.samples, d.params["delay_error_samples"] = dd, d.params["sigma_samples"] = de.sigma;
      d.magnitude = std::abs(dd);
      d.significant = std::abs(dd) > d.tolerance && std::abs(dd) > 3.0 * de.sigma;
      d.importance_um = std::abs(dd) / rr.fs_hz * rr.v_cmd.cwiseAbs().maxCoeff() * 1000.0 / std::sqrt(2.0);
      d.bic_drop = de.sigma > 0.0 ? (dd / de.sigma) * (dd / de.sigma) : 0.0;
      d.evidence = fmt("the PSD readings (through the DAQ filter, not the sensors) lag the reference by %.3f +- %.3f samples against %.3f nominal", de.samples,
                       de.sigma, rr.delay_samples);
      if (de.mounting_assumed) d.evidence += " (strips crossed at one speed: taken where run.toml puts them)";
      // What each sensor's own timing is once the delay is known. Both sensors off by the
      // same: their dynamics (2ζ/ω0); the head off against the table: the DAQ's skew between
      // their channels (run-format: "table and head channels are skewed in time") — the
      // simpler of two explanations only when the DAQ already shows a delay error; else one
      // sensor's own dynamics.
      if (dyn) {
        const double delay_us = -dd * 1e6 / rr.fs_hz;
        double own[2] = {NAN, NAN};
        for (int s2 = 0; s2 < 2; ++s2)
          if (auto it = dyn->params.find(std::string("damping_term_error_us_") + (s2 == 0 ? "table" : "head")); it != dyn->params.end())
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
            d.significant = dyn->bic_drop > o.min_bic_drop;
            d.evidence += fmt("; the head's channels lag the table's by %.2f samples more", skew);
          }
        }
        dyn->magnitude = std::abs(base);
        dyn->params["damping_term_error_us_after_delay"] = base;
        dyn->significant = dyn->bic_drop > o.min_bic_drop && std::abs(base) > dyn->tolerance;
        dyn->evidence += fmt("; %.1f us of it is the DAQ delay the PSD readings show", delay_us);
      }
      if (del) *del = d;
      else all.push_back(d);
    }
  } else if (del) {  // without strips and a reference the two are one shift: name the sensor's
    if (del->significant) {
      if (dyn && !dyn->significant) {
        dyn->significant = true, dyn->importance_um = del->importance_um;
        for (const auto& [k, v] : del->params) dyn->params[k] = v;
      }
      del->significant = false;
    }
    del->evidence += " (not separable from 2ζ/ω0 without PSD strips and a reference: reported as sensor.dynamics)";
    if (dyn) dyn->evidence += " (or daq.group_delay: the two shift the path alike without PSD strips and a reference)";
  }
  // Earth rate: known from the site, not fitted (on a circle a common scale error looks the
  // same); its size says whether it matters.
  {
    ExplainedEffect c;
    c.name = "site.coriolis", c.channel = "site", c.unit = "ug", c.tolerance = 1.0;
    const Eigen::Vector3d two_w = 2.0 * earth_rate_machine_radps(rr.meta.site);
    double peak = 0.0;
    for (int s2 = 0; s2 < rr.n; ++s2) peak = std::max(peak, two_w.cross(Eigen::Vector3d(rr.v_meas.row(s2).transpose()) * 1e-3).norm());
    c.magnitude = peak / (rr.meta.site.g_mps2 * 1e-6);
    c.params["peak_ug"] = c.magnitude;
    c.evidence = fmt("2 w x v of this motion peaks at %.2f ug from the site's latitude and heading; eical analyze --coriolis corrects it", c.magnitude);
    if (ExplainedEffect* fitted = find("site.coriolis")) {
      fitted->evidence += "; " + c.evidence;
      fitted->params["peak_ug"] = c.magnitude;
    } else {
      c.evidence += " (not fitted here: the motion does not separate it from a scale error)";
      all.push_back(c);
    }
  }
  // The bias at the standstills (ch. 8.3.2): steps between moves, drift, temperature.
  {
    const StandstillBias sb = standstill_bias(rr);
    const bool temp = sb.pattern == "temperature";
    ExplainedEffect b;
    b.name = temp ? "sensor.scale_temperature" : "sensor.bias_drift", b.channel = "standstills", b.unit = "ug", b.tolerance = 1.0;
    b.magnitude = sb.largest_change_ug, b.significant = sb.changed;
    b.bic_drop = sb.chi2 - sb.dof;
    b.params["largest_bias_change_ug"] = sb.largest_change_ug, b.params["standstills"] = static_cast<double>(sb.windows.size());
    if (temp) {
      b.params["bias_tc_error_ug_per_c"] = sb.temp_coeff_ug_per_c, b.params["temperature_change_c"] = sb.temperature_change_c;
      b.params["bias_tc_of_head"] = sb.temp_coeff_sensor == 1 ? 1.0 : 0.0;
    }
    else if (sb.pattern == "steps") b.params["step_ug"] = sb.step_ug;
    else if (sb.pattern == "drift") b.params["drift_ug_per_s"] = sb.drift_ug_per_s;
    // Ranking: the position error the change makes over a quarter-second move, µm.
    b.importance_um = sb.changed ? 0.5 * sb.largest_change_ug * rr.meta.site.g_mps2 * 0.0625 : 0.0;
    b.evidence = sb.evidence;
    if (ExplainedEffect* reg = find(b.name)) {
      reg->evidence += "; " + b.evidence;
      for (const auto& [k, v] : b.params) reg->params[k] = v;
      if (b.significant && !reg->significant) reg->importance_um = std::max(reg->importance_um, b.importance_um), reg->channel = "standstills";
      reg->significant = reg->significant || b.significant;
    } else {
      all.push_back(b);
    }
    // One cause for one change: the standstills say whether the bias followed the
    // temperature or the time; the integrated motion's drift group is the same change.
    const char* other = temp ? "sensor.bias_drift" : "sensor.scale_temperature";
    if (ExplainedEffect* oe = find(other); oe && oe->significant && sb.changed && (temp || sb.temperature_change_c < 0.05)) {
      oe->significant = false;
      oe->evidence += temp ? " (the drift follows the case temperature: see sensor.scale_temperature)" : " (the case temperature hardly changed: see sensor.bias_drift)";
    }
  }
  // Stick-slip: trains of slips while an axis creeps.
  {
    const StickSlipFinding ss = stick_slip_test(rr);
    ExplainedEffect x;
    x.name = "machine.stick_slip", x.channel = "acceleration", x.unit = "bursts per creep zone", x.tolerance = 8.0;
    x.magnitude = ss.bursts_per_zone, x.significant = ss.found;
    x.params["bursts_in_creep"] = ss.bursts_in_creep, x.params["bursts_elsewhere"] = ss.bursts_elsewhere, x.params["creep_zones"] = ss.creep_zones;
    if (ss.slip_um > 0.0) x.params["slip_um"] = ss.slip_um;
    if (ss.axis >= 0) x.params[std::string("axis_") + "xyz"[ss.axis]] = 1.0;
    x.importance_um = ss.found ? std::max(ss.slip_um, 1.0) : 0.0;
    x.bic_drop = ss.bursts_in_creep;
    x.evidence = ss.evidence;
    all.push_back(x);
  }
  // Vibration.
  {
    const VibrationTests v = vibration_tests(rr);
    ExplainedEffect c, d;
    c.name = "machine.common_vibration", c.channel = "spectrum", c.unit = "mg", c.tolerance = 0.05, c.magnitude = v.common.rms_mg;
    c.params["rms_mg"] = v.common.rms_mg, c.params["coherence"] = v.common.coherence;
    for (std::size_t i = 0; i < v.common.lines.size(); ++i) c.params["line" + std::to_string(i) + "_hz"] = v.common.lines[i].freq_hz;
    c.significant = v.common.found && v.common.rms_mg > c.tolerance;
    c.importance_um = c.significant ? 1.0 + v.common.rms_mg : 0.0;
    c.evidence = v.common.evidence;
    d.name = "machine.differential_vibration", d.channel = "spectrum", d.unit = "um", d.tolerance = 0.1, d.magnitude = v.differential.displacement_um;
    d.params["rms_mg"] = v.differential.rms_mg, d.params["displacement_um"] = v.differential.displacement_um;
    for (std::size_t i = 0; i < v.differential.lines.size(); ++i) d.params["line" + std::to_string(i) + "_hz"] = v.differential.lines[i].freq_hz;
    // Relative motion that matters for the position (0.1 µm), or an acceleration ten times
    // the sensors' own noise over the band (0.3 mg RMS) that a light structure shows.
    d.significant = v.differential.found && (v.differential.displacement_um > d.tolerance || v.differential.rms_mg > 0.3);
    d.importance_um = d.significant ? v.differential.displacement_um : 0.0;
    d.evidence = v.differential.evidence;
    // Modes the motion drives: the frequency response of the measured relative acceleration
    // over the commanded one. Measured by both sensors it is the head moving against the
    // table (differential vibration); with one sensor it is the structure between the drive
    // and the measured point (machine.resonance).
    ExplainedEffect res;
    res.name = "machine.resonance", res.channel = "frequency response", res.unit = "amplification", res.tolerance = 0.1;
    // Up to a third of the slowest sensor's natural frequency: above it the sensor's own
    // dynamics (what explain tests as sensor.dynamics) and the DAQ filter shape the response.
    double f0_min = INFINITY;
    for (int sn = 0; sn < 2; ++sn)
      if (rr.meta.sensor_present[sn]) f0_min = std::min(f0_min, rr.meta.sensors[sn].f0_hz);
    const ModeSearch ms = find_structural_modes(rr.a_meas, rr.a_cmd, 1.0 / rr.dt_s, rr.moving, std::min(kModeMaxHz, f0_min / 3.0));
    const bool relative = rr.meta.sensor_present[0] && rr.meta.sensor_present[1];
    ExplainedEffect& named = relative ? d : res;
    int k = 0;
    double largest = 0.0;
    for (const auto& md : ms.modes) {
      if (!md.significant) continue;
      const std::string pre = "mode" + std::to_string(k++) + "_";
      named.params[pre + "frequency_hz"] = md.frequency_hz, named.params[pre + "sigma_frequency_hz"] = md.sigma_frequency_hz;
      named.params[pre + "damping_ratio"] = md.damping_ratio, named.params[pre + "sigma_damping_ratio"] = md.sigma_damping_ratio;
      named.params[pre + "gain"] = md.gain, named.params[pre + "peak_amplification"] = md.peak_amplification;
      for (int a = 0; a < 3; ++a) named.params[pre + "direction_" + "xyz"[a]] = md.direction[static_cast<std::size_t>(a)];
      named.evidence += fmt("; a mode at %.2f +- %.2f Hz, damping %.3f +- %.3f, ", md.frequency_hz, md.sigma_frequency_hz, md.damping_ratio, md.sigma_damping_ratio) +
                        fmt("gain %.3f (x%.2f at its peak), driven along ", md.gain, 1.0 + md.peak_amplification) + std::string(1, "xyz"[md.input_axis]) +
                        fmt(", %.2f mg / %.2f um RMS in this run; chi2 drop %.0f against %.0f, coherence %.2f", md.response_rms_mg, md.displacement_rms_um, md.chi2_drop,
                            md.chi2_threshold, md.coherence);
      named.params[pre + "displacement_rms_um"] = md.displacement_rms_um;
      largest = std::max(largest, md.peak_amplification);
    }
    if (k > 0) {
      named.significant = true;
      named.magnitude = std::max(named.magnitude, largest);
      named.importance_um = std::max(named.importance_um, 1.0 + largest);
      named.evidence = (relative ? "head against table: " : "") + named.evidence;
    }
    res.evidence = (k > 0 ? "the " : "") + res.evidence + (res.evidence.empty() ? ms.evidence + (k == 0 ? ": no mode stands out" : "") : "; " + ms.evidence);
    if (k > 0 && relative) res.evidence = ms.evidence + ": the modes found are real relative motion of the two sensors (machine.differential_vibration)";
    all.push_back(c), all.push_back(d), all.push_back(res);
  }
  // The gain: the pipeline's path against each axis' reference, with the nominal model and
  // with the extended one (the significant sensor effects in the sensors, the machine
  // effects of set-point-only axes subtracted). A sensor-side extension is taken into the
  // model only when the pipeline with it follows the reference better: one at a time, the
  // most important first (a fit can be significant and still not transfer to the pipeline).
  {
    auto moving_rms = [&](const Eigen::VectorXd& v, const Channel& ch) { return moving_axes_rms(rr, v, ch); };
    // The machine effects of set-point-only axes, predicted on a channel's rows.
    auto machine_prediction = [&](const Channel& ch) {
      Eigen::VectorXd pred = Eigen::VectorXd::Zero(ch.rows());
      for (const auto& e : all) {
        if (!e.significant || e.channel != "total") continue;
        const auto it = std::find_if(machine.begin(), machine.end(), [&](const EffectModel& m) { return m.name == e.name; });
        if (it == machine.end()) continue;
        Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(it->params.size()));
        for (std::size_t p = 0; p < it->params.size(); ++p)
          if (auto f = e.params.find(it->params[p]); f != e.params.end()) full[static_cast<Eigen::Index>(p)] = f->second;
        const Eigen::MatrixXd cols = columns_on(*it, ch);
        for (Eigen::Index i = 0; i < ch.rows(); ++i)
          if (cmd_axes[static_cast<std::size_t>(ch.axis[static_cast<std::size_t>(i)])]) pred[i] += cols.row(i).dot(full);
      }
      return pred;
    };
    // The pipeline's residual with the sensor-side effects `taken` in the model.
    auto with_model = [&](const std::vector<ExplainedEffect>& taken) {
      Channel ch = build_residuals(extended_run(run, taken)).pipeline;
      ch.residual_um -= machine_prediction(ch);
      return ch;
    };
    const Eigen::VectorXd before_v = offsets_out(rr.pipeline);
    ex.nominal_residual_rms_um = moving_rms(before_v, rr.pipeline);
    Channel after_ch = rr.pipeline;
    after_ch.residual_um -= machine_prediction(after_ch);
    double best = moving_rms(offsets_out(after_ch), after_ch);
    static const char* kPipelineSide[] = {"sensor.scale", "sensor.misalignment", "sensor.cross_coupling", "sensor.nonlinearity", "sensor.dynamics",
                                          "sensor.damping_amplitude", "sensor.scale_temperature", "daq.group_delay"};
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < all.size(); ++k)
      if (all[k].significant && std::any_of(std::begin(kPipelineSide), std::end(kPipelineSide), [&](const char* n) { return all[k].name == n; }))
        order.push_back(k);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return all[a].importance_um > all[b].importance_um; });
    std::vector<ExplainedEffect> taken;
    for (std::size_t k : order) {
      std::vector<ExplainedEffect> trial = taken;
      trial.push_back(all[k]);
      Channel ch = with_model(trial);
      const double r = moving_rms(offsets_out(ch), ch);
      if (r < best) {
        best = r, after_ch = std::move(ch), taken = std::move(trial);
        all[k].taken_into_model = true;
      } else {
        all[k].evidence += fmt("; not taken into the model: the pipeline with it follows the reference no better (%.3f -> %.3f um)", best, r);
      }
    }
    const Eigen::VectorXd after_v = offsets_out(after_ch);
    ex.final_residual_rms_um = best;
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
    ex.traces.push_back(std::move(tr));
  }
  // Significant first — the table's effects before what lies outside it (other.*: a
  // residual no effect explains at a plausible size is named once the named ones are) —
  // the one that explains most first.
  std::stable_sort(all.begin(), all.end(), [](const ExplainedEffect& a, const ExplainedEffect& b) {
    if (a.significant != b.significant) return a.significant;
    const bool ao = a.name.rfind("other.", 0) == 0, bo = b.name.rfind("other.", 0) == 0;
    if (a.significant && ao != bo) return bo;
    if (a.significant) return a.importance_um > b.importance_um;
    return a.bic_drop > b.bic_drop;
  });
  ex.effects = std::move(all);
  ex.correlations = regressor_correlations(rr);
  return ex;
}

}  // namespace eical::dsp::model
