#include "dsp/model/kf_selection.hpp"

#include "dsp/core/float_limits.hpp"
#include "dsp/identify/augmented_filter.hpp"
#include "dsp/model/effect_selection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

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

}  // namespace

KfSelection select_groups_kf(const std::array<AxisTrack, 3>& tracks, const std::vector<ParamGroup>& groups,
                             const fusion::ErrorModel& model, const KfSelectionOptions& o,
                             const std::vector<AxisParam>& base) {
  KfSelection out;
  auto fit = [&](int a, const std::vector<const AxisParam*>& ps, bool keep = false) {
    return tracks[a].present ? fit_axis(tracks[a], ps, model, o.zupt_sigma_um_s, keep) : AxisFit{};
  };
  Model cur;
  for (const auto& p : base) cur.params[static_cast<std::size_t>(p.axis)].push_back(&p);
  std::vector<double> base_innov;
  for (int a = 0; a < 3; ++a) {
    cur.fit[a] = fit(a, cur.params[static_cast<std::size_t>(a)], true);
    base_innov.insert(base_innov.end(), cur.fit[a].innovations.begin(), cur.fit[a].innovations.end());
  }
  auto sums = [](const Model& m, double& fs, std::size_t& fn, double& hs, std::size_t& hn) {
    fs = hs = 0.0, fn = hn = 0;
    for (const auto& f : m.fit) fs += f.fit_ss, fn += f.fit_n, hs += f.held_ss, hn += f.held_n;
  };
  double fs = 0.0, hs = 0.0;
  std::size_t fn = 0, hn = 0;
  sums(cur, fs, fn, hs, hn);
  out.fit_rms_nominal_um = rms(fs, fn), out.held_rms_nominal_um = rms(hs, hn);
  if (fn < 20) return out;
  const Eigen::VectorXd bi =
      Eigen::Map<const Eigen::VectorXd>(base_innov.data(), static_cast<Eigen::Index>(base_innov.size()));
  out.n_eff = static_cast<double>(fn) / integrated_autocorrelation_time(bi, 2000);
  const double ln_n = std::log(std::max(out.n_eff, 2.0));
  // The log-likelihood of correlated innovations counts each of them too often: scale it
  // by the effective count, as the BIC's penalty is.
  const double scale = out.n_eff / static_cast<double>(fn);

  auto with = [&](const Model& from, const ParamGroup& gp) {
    Model m = from;
    std::array<bool, 3> touched{};
    for (const auto& p : gp.params) m.params[p.axis].push_back(&p), touched[p.axis] = true, ++m.k;
    for (int a = 0; a < 3; ++a)
      if (touched[a]) m.fit[a] = fit(a, m.params[a]);
    return m;
  };
  auto verdict = [&](const Model& before, const Model& after, const ParamGroup& gp) {
    GroupVerdict v;
    v.name = gp.name;
    v.loglik_gain = 2.0 * scale * (total_logl(after) - total_logl(before));
    v.bic_drop = v.loglik_gain - static_cast<double>(after.k - before.k) * ln_n;
    double a_fs, a_hs, b_fs, b_hs;
    std::size_t a_fn, a_hn, b_fn, b_hn;
    sums(before, b_fs, b_fn, b_hs, b_hn), sums(after, a_fs, a_fn, a_hs, a_hn);
    v.fit_rms_before_um = rms(b_fs, b_fn), v.fit_rms_after_um = rms(a_fs, a_fn);
    v.held_rms_before_um = rms(b_hs, b_hn), v.held_rms_after_um = rms(a_hs, a_hn);
    v.held_score_gain = scale * (total_held_lpd(after) - total_held_lpd(before));
    for (int a = 0; a < 3; ++a)
      for (std::size_t j = 0; j < after.params[a].size(); ++j)
        for (const auto& p : gp.params)
          if (&p == after.params[a][j])
            v.value[p.name] = after.fit[a].value[static_cast<Eigen::Index>(j)],
            v.sigma[p.name] = after.fit[a].sigma[static_cast<Eigen::Index>(j)];
    return v;
  };
  std::vector<bool> done(groups.size(), false);
  for (int round = 0; round < o.max_groups; ++round) {
    struct Trial {
      std::size_t g;
      GroupVerdict v;
      Model m;
    };
    std::vector<Trial> trials;
    double top_bic = -kInf;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      if (done[g] || groups[g].params.empty() || groups[g].known) continue;
      Model m = with(cur, groups[g]);
      GroupVerdict v = verdict(cur, m, groups[g]);
      // Only an extension that also predicts the held-out data better may be taken.
      // The score is the held-out observations' log predictive density (in effective
      // counts, as the BIC): it weighs each prediction by how well it could be known.
      const bool gain = v.held_score_gain > o.min_heldout_score_gain;
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
    if (!pick || pick->v.bic_drop < o.min_bic_drop) break;
    const int best = static_cast<int>(pick->g);
    GroupVerdict best_v = pick->v;
    Model best_m = pick->m;
    best_v.accepted = true;
    done[static_cast<std::size_t>(best)] = true;
    cur = std::move(best_m);
    out.groups.push_back(best_v);
  }
  // Known groups the run shows join the final model: their size is not a free choice, so
  // no BIC penalty is charged, only the evidence that the run carries them.
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (done[g] || groups[g].params.empty() || !groups[g].known) continue;
    Model m = with(cur, groups[g]);
    GroupVerdict v = verdict(cur, m, groups[g]);
    if (v.loglik_gain < o.known_min_loglik_gain || v.held_score_gain < 0.0) continue;
    v.accepted = true;
    done[g] = true;
    cur = std::move(m);
    out.groups.push_back(std::move(v));
  }
  // The accepted groups' final values (fitted together), then every other group once more
  // against the final model.
  for (auto& v : out.groups)
    for (int a = 0; a < 3; ++a)
      for (std::size_t j = 0; j < cur.params[a].size(); ++j)
        if (v.value.count(cur.params[a][j]->name)) {
          v.value[cur.params[a][j]->name] = cur.fit[a].value[static_cast<Eigen::Index>(j)];
          v.sigma[cur.params[a][j]->name] = cur.fit[a].sigma[static_cast<Eigen::Index>(j)];
        }
  sums(cur, fs, fn, hs, hn);
  out.fit_rms_final_um = rms(fs, fn), out.held_rms_final_um = rms(hs, hn);
  {
    double var = 0.0;
    for (const auto& f : cur.fit) var += f.held_var;
    out.held_expected_rms_final_um = rms(var, hn);
  }
  {
    Model all = cur;
    for (std::size_t g = 0; g < groups.size(); ++g)
      if (!done[g] && !groups[g].params.empty() && !groups[g].known) all = with(all, groups[g]);
    double afs, ahs, var = 0.0;
    std::size_t afn, ahn;
    sums(all, afs, afn, ahs, ahn);
    for (const auto& f : all.fit) var += f.held_var;
    out.held_rms_all_um = rms(ahs, ahn), out.held_expected_rms_all_um = rms(var, ahn);
  }
  for (int a = 0; a < 3; ++a)
    for (std::size_t j = 0; j < cur.params[a].size(); ++j)
      for (const auto& p : base)
        if (&p == cur.params[a][j])
          out.base_value[p.name] = cur.fit[a].value[static_cast<Eigen::Index>(j)],
          out.base_sigma[p.name] = cur.fit[a].sigma[static_cast<Eigen::Index>(j)];
  std::vector<GroupVerdict> rest;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (done[g] || groups[g].params.empty()) continue;
    rest.push_back(verdict(cur, with(cur, groups[g]), groups[g]));
  }
  std::sort(rest.begin(), rest.end(), [](const auto& a, const auto& b) { return a.bic_drop > b.bic_drop; });
  out.groups.insert(out.groups.end(), rest.begin(), rest.end());
  return out;
}

}  // namespace eical::dsp::model
