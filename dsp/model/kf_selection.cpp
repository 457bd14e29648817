#include "dsp/model/kf_selection.hpp"

#include "dsp/core/float_limits.hpp"
#include "dsp/identify/augmented_filter.hpp"
#include "dsp/model/effect_selection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace eical::dsp::model {
namespace {

constexpr double kTagPrior = 50.0;  // µm: a strip's mounting
constexpr double kTieBic = 6.0;     // Kass–Raftery: below 6, no strong evidence either way

struct AxisFit {
  double logl = 0.0, fit_ss = 0.0, held_ss = 0.0;
  double held_lpd = 0.0;  // log predictive density of the held-out observations (a proper score)
  double held_var = 0.0;  // sum of their predictive variances (what the model expects of them)
  std::size_t fit_n = 0, held_n = 0;
  Eigen::VectorXd value, sigma;
  std::vector<double> innovations;  // of the fitting observations (for the effective count)
};

AxisFit fit_axis(const AxisTrack& t, const std::vector<const AxisParam*>& ps, const fusion::ErrorModel& model,
                 double zupt_sigma, bool keep_innov) {
  const auto p = static_cast<Eigen::Index>(ps.size());
  Eigen::VectorXd prior(p + t.tags);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(p + t.tags);
  for (Eigen::Index j = 0; j < p; ++j)
    prior[j] = ps[static_cast<std::size_t>(j)]->prior_sigma, mean[j] = ps[static_cast<std::size_t>(j)]->prior_mean;
  for (int k = 0; k < t.tags; ++k) prior[p + k] = kTagPrior;
  identify::AugmentedFilter f(
      model, Eigen::Vector3d(50.0, 1.0, std::hypot(model.bias_step_um_s2, t.start_bias_sigma_um_s2)), prior, mean);
  const Eigen::Index n = t.h_s.size();
  Eigen::VectorXd g = Eigen::VectorXd::Zero(p + t.tags);
  Eigen::RowVectorXd zrow = Eigen::RowVectorXd::Zero(3 + p + t.tags);
  zrow[1] = 1.0;
  AxisFit out;
  std::vector<bool> tag_seen(static_cast<std::size_t>(t.tags), false);
  std::size_t next = 0;
  for (Eigen::Index s = 0; s < n; ++s) {
    if (s > 0) {
      for (Eigen::Index j = 0; j < p; ++j) {
        const AxisParam& ap = *ps[static_cast<std::size_t>(j)];
        g[j] = ap.accel ? 0.5 * (ap.input[s - 1] + ap.input[s]) : 0.0;
      }
      f.predict(t.h_s[s], g, t.bias_step[static_cast<std::size_t>(s)] != 0);
    }
    if (t.zupt[static_cast<std::size_t>(s)]) {
      f.update(zrow, t.v_um_s[s], zupt_sigma);
      out.logl += f.last_log_density();
    }
    for (; next < t.obs.size() && t.obs[next].sample == s; ++next) {
      const AxisTrack::Obs& o = t.obs[next];
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(3 + p + t.tags);
      row[0] = 1.0;
      for (Eigen::Index j = 0; j < p; ++j) {
        const AxisParam& ap = *ps[static_cast<std::size_t>(j)];
        if (!ap.accel) row[3 + j] = ap.input[s];
      }
      if (o.tag >= 0) row[3 + p + o.tag] = -1.0;
      if (o.heldout) {
        double nu = 0.0, var = 0.0;
        f.predict_observation(row, o.z_um, o.sigma_um, nu, var);
        out.held_lpd += -0.5 * (std::log(2.0 * std::numbers::pi * var) + nu * nu / var);
        // A strip not yet seen in the fitting observations has an unknown mounting: its
        // prediction says nothing about the model (the score above weighs it by its variance).
        if (o.tag < 0 || tag_seen[static_cast<std::size_t>(o.tag)])
          out.held_ss += nu * nu, out.held_var += var, ++out.held_n;
      } else {
        if (o.tag >= 0) tag_seen[static_cast<std::size_t>(o.tag)] = true;
        f.update(row, o.z_um, o.sigma_um);
        out.logl += f.last_log_density();
        out.fit_ss += f.last_innovation() * f.last_innovation(), ++out.fit_n;
        if (keep_innov) out.innovations.push_back(f.last_innovation());
      }
    }
  }
  out.value.resize(p), out.sigma.resize(p);
  for (Eigen::Index j = 0; j < p; ++j)
    out.value[j] = f.parameter(static_cast<int>(j)), out.sigma[j] = f.parameter_sigma(static_cast<int>(j));
  return out;
}

struct Model {
  std::array<std::vector<const AxisParam*>, 3> params;
  std::array<AxisFit, 3> fit;
  int k = 0;
};

double total_logl(const Model& m) { return m.fit[0].logl + m.fit[1].logl + m.fit[2].logl; }
double total_held_lpd(const Model& m) { return m.fit[0].held_lpd + m.fit[1].held_lpd + m.fit[2].held_lpd; }

double rms(double ss, std::size_t n) { return n ? std::sqrt(ss / static_cast<double>(n)) : 0.0; }

// A model's squared innovations and counts, fitting and held-out observations summed over the axes.
struct InnovationSums {
  double fit_ss = 0.0, held_ss = 0.0;
  std::size_t fit_n = 0, held_n = 0;
};

InnovationSums innovation_sums(const Model& m) {
  InnovationSums s;
  for (const auto& f : m.fit) s.fit_ss += f.fit_ss, s.fit_n += f.fit_n, s.held_ss += f.held_ss, s.held_n += f.held_n;
  return s;
}

// The sum of a model's held-out predictive variances.
double held_variance(const Model& m) {
  double var = 0.0;
  for (const auto& f : m.fit) var += f.held_var;
  return var;
}

// Axis a's track through the filter with parameters ps (an axis without a track: no fit).
AxisFit fit_track(const std::array<AxisTrack, 3>& tracks, const fusion::ErrorModel& model, const KfSelectionOptions& o,
                  int a, const std::vector<const AxisParam*>& ps, bool keep = false) {
  return tracks[a].present ? fit_axis(tracks[a], ps, model, o.zupt_sigma_um_s, keep) : AxisFit{};
}

// What every model of the selection is fitted and scored with.
struct Selector {
  const std::array<AxisTrack, 3>& tracks;
  const fusion::ErrorModel& model;
  const KfSelectionOptions& o;
  // The log-likelihood of correlated innovations counts each of them too often: it is
  // scaled by the effective count, as the BIC's penalty (ln n_eff) is.
  double scale = 1.0, ln_n = 0.0;

  [[nodiscard]] AxisFit fit(int a, const std::vector<const AxisParam*>& ps) const {
    return fit_track(tracks, model, o, a, ps);
  }
};

// `from` with a group's parameters added, the axes it touches refitted.
Model with_group(const Selector& sel, const Model& from, const ParamGroup& gp) {
  Model m = from;
  std::array<bool, 3> touched{};
  for (const auto& p : gp.params) m.params[p.axis].push_back(&p), touched[p.axis] = true, ++m.k;
  for (int a = 0; a < 3; ++a)
    if (touched[a]) m.fit[a] = sel.fit(a, m.params[a]);
  return m;
}

// What a group gains from `before` to `after`: BIC drop, RMS, held-out score, its values.
GroupVerdict verdict(const Selector& sel, const Model& before, const Model& after, const ParamGroup& gp) {
  GroupVerdict v;
  v.name = gp.name;
  v.loglik_gain = 2.0 * sel.scale * (total_logl(after) - total_logl(before));
  v.bic_drop = v.loglik_gain - static_cast<double>(after.k - before.k) * sel.ln_n;
  const InnovationSums b = innovation_sums(before), a = innovation_sums(after);
  v.fit_rms_before_um = rms(b.fit_ss, b.fit_n), v.fit_rms_after_um = rms(a.fit_ss, a.fit_n);
  v.held_rms_before_um = rms(b.held_ss, b.held_n), v.held_rms_after_um = rms(a.held_ss, a.held_n);
  v.held_score_gain = sel.scale * (total_held_lpd(after) - total_held_lpd(before));
  for (int ax = 0; ax < 3; ++ax)
    for (std::size_t j = 0; j < after.params[ax].size(); ++j)
      for (const auto& p : gp.params)
        if (&p == after.params[ax][j])
          v.value[p.name] = after.fit[ax].value[static_cast<Eigen::Index>(j)],
          v.sigma[p.name] = after.fit[ax].sigma[static_cast<Eigen::Index>(j)];
  return v;
}

// The base model (its parameters on every axis), fitted; the innovations it leaves.
Model base_model(const std::array<AxisTrack, 3>& tracks, const fusion::ErrorModel& model, const KfSelectionOptions& o,
                 const std::vector<AxisParam>& base, std::vector<double>& base_innov) {
  Model cur;
  for (const auto& p : base) cur.params[static_cast<std::size_t>(p.axis)].push_back(&p);
  for (int a = 0; a < 3; ++a) {
    cur.fit[a] = fit_track(tracks, model, o, a, cur.params[static_cast<std::size_t>(a)], true);
    base_innov.insert(base_innov.end(), cur.fit[a].innovations.begin(), cur.fit[a].innovations.end());
  }
  return cur;
}

// One round of the forward selection: the group to take, if any. Only an extension that
// also predicts the held-out data better may be taken; groups the BIC cannot tell apart
// are decided by the held-out prediction.
struct Trial {
  std::size_t g = 0;
  GroupVerdict v;
  Model m;
};

std::optional<Trial> best_trial(const Selector& sel, const std::vector<ParamGroup>& groups, const Model& cur,
                                const std::vector<bool>& done) {
  std::vector<Trial> trials;
  double top_bic = -kInf;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (done[g] || groups[g].params.empty() || groups[g].known) continue;
    Model m = with_group(sel, cur, groups[g]);
    GroupVerdict v = verdict(sel, cur, m, groups[g]);
    // The score is the held-out observations' log predictive density (in effective
    // counts, as the BIC): it weighs each prediction by how well it could be known.
    const bool gain = v.held_score_gain > sel.o.min_heldout_score_gain;
    if (!gain) continue;
    top_bic = std::max(top_bic, v.bic_drop);
    trials.push_back({g, std::move(v), std::move(m)});
  }
  // Groups the BIC cannot tell apart (within kTieBic: less than "strong" evidence for
  // one over the other — ζ(|a|) and a constant ζ error in a move of one acceleration
  // level) are decided by what predicts the held-out observations better.
  const Trial* pick = nullptr;
  for (const auto& t : trials)
    if (t.v.bic_drop >= top_bic - kTieBic && (!pick || t.v.held_rms_after_um < pick->v.held_rms_after_um)) pick = &t;
  if (!pick || pick->v.bic_drop < sel.o.min_bic_drop) return std::nullopt;
  return *pick;
}

// Forward selection: the best group per round into the model while the BIC says so.
void select_forward(const Selector& sel, const std::vector<ParamGroup>& groups, Model& cur, std::vector<bool>& done,
                    KfSelection& out) {
  for (int round = 0; round < sel.o.max_groups; ++round) {
    std::optional<Trial> pick = best_trial(sel, groups, cur, done);
    if (!pick) break;
    pick->v.accepted = true;
    done[pick->g] = true;
    cur = std::move(pick->m);
    out.groups.push_back(std::move(pick->v));
  }
}

// Known groups the run shows join the final model: their size is not a free choice, so
// no BIC penalty is charged, only the evidence that the run carries them.
void add_known_groups(const Selector& sel, const std::vector<ParamGroup>& groups, Model& cur, std::vector<bool>& done,
                      KfSelection& out) {
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (done[g] || groups[g].params.empty() || !groups[g].known) continue;
    Model m = with_group(sel, cur, groups[g]);
    GroupVerdict v = verdict(sel, cur, m, groups[g]);
    if (v.loglik_gain < sel.o.known_min_loglik_gain || v.held_score_gain < 0.0) continue;
    v.accepted = true;
    done[g] = true;
    cur = std::move(m);
    out.groups.push_back(std::move(v));
  }
}

// The accepted groups' final values (fitted together).
void final_values(const Model& cur, std::vector<GroupVerdict>& accepted) {
  for (auto& v : accepted)
    for (int a = 0; a < 3; ++a)
      for (std::size_t j = 0; j < cur.params[a].size(); ++j)
        if (v.value.count(cur.params[a][j]->name)) {
          v.value[cur.params[a][j]->name] = cur.fit[a].value[static_cast<Eigen::Index>(j)];
          v.sigma[cur.params[a][j]->name] = cur.fit[a].sigma[static_cast<Eigen::Index>(j)];
        }
}

// The held-out RMS with every group of the table in the model at once, and what that
// model expects there.
void all_groups_rms(const Selector& sel, const std::vector<ParamGroup>& groups, const Model& cur,
                    const std::vector<bool>& done, KfSelection& out) {
  Model all = cur;
  for (std::size_t g = 0; g < groups.size(); ++g)
    if (!done[g] && !groups[g].params.empty() && !groups[g].known) all = with_group(sel, all, groups[g]);
  const InnovationSums s = innovation_sums(all);
  out.held_rms_all_um = rms(s.held_ss, s.held_n), out.held_expected_rms_all_um = rms(held_variance(all), s.held_n);
}

// The base parameters' values in the final model.
void base_values(const Model& cur, const std::vector<AxisParam>& base, KfSelection& out) {
  for (int a = 0; a < 3; ++a)
    for (std::size_t j = 0; j < cur.params[a].size(); ++j)
      for (const auto& p : base)
        if (&p == cur.params[a][j])
          out.base_value[p.name] = cur.fit[a].value[static_cast<Eigen::Index>(j)],
          out.base_sigma[p.name] = cur.fit[a].sigma[static_cast<Eigen::Index>(j)];
}

// Every group not taken, once more against the final model, by BIC drop.
std::vector<GroupVerdict> rest_verdicts(const Selector& sel, const std::vector<ParamGroup>& groups, const Model& cur,
                                        const std::vector<bool>& done) {
  std::vector<GroupVerdict> rest;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (done[g] || groups[g].params.empty()) continue;
    rest.push_back(verdict(sel, cur, with_group(sel, cur, groups[g]), groups[g]));
  }
  std::sort(rest.begin(), rest.end(), [](const auto& a, const auto& b) { return a.bic_drop > b.bic_drop; });
  return rest;
}

}  // namespace

KfSelection select_groups_kf(const std::array<AxisTrack, 3>& tracks, const std::vector<ParamGroup>& groups,
                             const fusion::ErrorModel& model, const KfSelectionOptions& options,
                             const std::vector<AxisParam>& base) {
  KfSelection out;
  std::vector<double> base_innov;
  Model cur = base_model(tracks, model, options, base, base_innov);
  const InnovationSums nominal = innovation_sums(cur);
  out.fit_rms_nominal_um = rms(nominal.fit_ss, nominal.fit_n);
  out.held_rms_nominal_um = rms(nominal.held_ss, nominal.held_n);
  if (nominal.fit_n < 20) return out;
  const Eigen::VectorXd bi =
      Eigen::Map<const Eigen::VectorXd>(base_innov.data(), static_cast<Eigen::Index>(base_innov.size()));
  out.n_eff = static_cast<double>(nominal.fit_n) / integrated_autocorrelation_time(bi, 2000);
  const Selector sel{.tracks = tracks,
                     .model = model,
                     .o = options,
                     .scale = out.n_eff / static_cast<double>(nominal.fit_n),
                     .ln_n = std::log(std::max(out.n_eff, 2.0))};

  std::vector<bool> done(groups.size(), false);
  select_forward(sel, groups, cur, done, out);
  add_known_groups(sel, groups, cur, done, out);
  // The accepted groups' final values, then every other group once more against the final model.
  final_values(cur, out.groups);
  const InnovationSums final_sums = innovation_sums(cur);
  out.fit_rms_final_um = rms(final_sums.fit_ss, final_sums.fit_n);
  out.held_rms_final_um = rms(final_sums.held_ss, final_sums.held_n);
  out.held_expected_rms_final_um = rms(held_variance(cur), final_sums.held_n);
  all_groups_rms(sel, groups, cur, done, out);
  base_values(cur, base, out);
  const std::vector<GroupVerdict> rest = rest_verdicts(sel, groups, cur, done);
  out.groups.insert(out.groups.end(), rest.begin(), rest.end());
  return out;
}

}  // namespace eical::dsp::model
