#include "dsp/fusion/rts_smoother.hpp"

#include "dsp/core/error.hpp"
#include "dsp/fusion/forward_filter.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace eical::dsp::fusion {
namespace {

// F and Q for the step into sample k (the nominal step is computed once).
struct Steps {
  const std::vector<std::int64_t>& idx;
  double fs_hz;
  const ErrorModel& model;
  Discrete nominal;
  Steps(const std::vector<std::int64_t>& i, double fs, const ErrorModel& m)
      : idx(i), fs_hz(fs), model(m), nominal(discretise(m, 1.0 / fs)) {}
  [[nodiscard]] Discrete into(std::size_t k) const {
    const std::int64_t gap = idx[k] - idx[k - 1];
    return gap == 1 ? nominal : discretise(model, static_cast<double>(gap) / fs_hz);
  }
};

}  // namespace

SmootherOutput smooth(const SmootherInput& in) {
  if (!in.sample_index || !in.vel_mm_s || !in.pos_mm || !in.schedule) throw InputError("smoother: input arrays missing");
  const std::size_t n = in.sample_index->size();
  const auto& flags = in.schedule->flags;
  if (in.vel_mm_s->size() != n || in.pos_mm->size() != n || flags.size() != n)
    throw InputError("smoother: trace, velocity and schedule differ in length");
  SmootherOutput out;
  if (n == 0) return out;
  const ErrorModel& m = in.model;
  const Steps steps(*in.sample_index, in.fs_hz, m);
  std::vector<PositionFix> fixes = in.schedule->fixes;  // in sample order, whatever the caller's
  std::stable_sort(fixes.begin(), fixes.end(), [](const PositionFix& a, const PositionFix& b) { return a.k < b.k; });

  // Forward: the live filter's code over the stored trace.
  std::array<std::vector<Vec3>, 3> ef;
  std::array<std::vector<Mat3>, 3> pf;
  for (int a = 0; a < 3; ++a) ef[a].resize(n), pf[a].resize(n);
  ForwardFilter fwd;
  fwd.start(m, in.start_bias_sigma_um_s2);
  std::vector<CovarianceReset> resets;
  resets.reserve(4096);
  fwd.resets = &resets;
  std::vector<VelocityMean> means = in.schedule->velocity_means;
  std::stable_sort(means.begin(), means.end(), [](const VelocityMean& a, const VelocityMean& b) { return a.k < b.k; });
  std::size_t next_fix = 0, next_mean = 0;
  for (std::size_t k = 0; k < n; ++k) {
    fwd.k = k;
    if (k > 0) fwd.predict(steps.into(k), (flags[k] & schedule_flag::move_start) != 0, m);
    const auto& zs = in.schedule->zupt_sigma_um_s;
    fwd.velocity_supports(flags[k], (*in.vel_mm_s)[k] * 1000.0, m, k < zs.size() ? static_cast<double>(zs[k]) : 0.0, in.schedule->zupt);
    for (; next_mean < means.size() && means[next_mean].k <= k; ++next_mean)
      if (means[next_mean].k == k) fwd.velocity_mean(means[next_mean], m, in.schedule->zupt);
    for (; next_fix < fixes.size() && fixes[next_fix].k == k; ++next_fix) {
      const PositionFix& f = fixes[next_fix];
      if (in.schedule->cupt) fwd.position_fix(f.axis, (*in.pos_mm)[k][f.axis] * 1000.0, f.position_um, std::hypot(f.sigma_um, f.model_sigma_um), m);
    }
    for (int a = 0; a < 3; ++a) ef[a][k] = fwd.axis[a].e, pf[a][k] = fwd.axis[a].P;
  }
  out.tally = fwd.tally;
  out.resets = fwd.reset_count;
  // Per axis and sample: the process noise a reset added (the backward pass needs it).
  std::array<std::vector<std::pair<std::size_t, Vec3>>, 3> extra;
  for (const auto& r : resets) extra[r.axis].push_back({r.k, Vec3(r.add_xx, r.add_vv, r.add_bb)});

  // Backward (RTS), in place over the forward arrays.
  out.dx_um.assign(n, Eigen::Vector3d::Zero());
  out.dv_um_s.assign(n, Eigen::Vector3d::Zero());
  out.bias_um_s2.assign(n, Eigen::Vector3d::Zero());
  out.sigma_x_um.assign(n, Eigen::Vector3d::Zero());
  if (in.keep_gains)
    for (int a = 0; a < 3; ++a) out.gain[a].assign(n, Mat3::Zero()), out.p_smoothed[a].assign(n, Mat3::Zero());
  for (int a = 0; a < 3; ++a) {
    auto& e = ef[a];
    auto& p = pf[a];
    std::size_t next_extra = extra[a].size();
    for (std::size_t k = in.forward_only ? 0 : n - 1; k-- > 0;) {
      const Discrete d = steps.into(k + 1);
      Mat3 pp = d.F * p[k] * d.F.transpose() + d.Q;
      if (flags[k + 1] & schedule_flag::move_start) pp(2, 2) += m.bias_step_um_s2 * m.bias_step_um_s2;
      while (next_extra > 0 && extra[a][next_extra - 1].first > k + 1) --next_extra;
      for (std::size_t r = next_extra; r > 0 && extra[a][r - 1].first == k + 1; --r) pp.diagonal() += extra[a][r - 1].second;
      const Vec3 ep = d.F * e[k];
      const Mat3 c = pp.ldlt().solve(d.F * p[k].transpose()).transpose();  // P_k Fᵀ P⁻¹ (P⁻ symmetric)
      e[k] += c * (e[k + 1] - ep);
      p[k] += c * (p[k + 1] - pp) * c.transpose();
      p[k] = 0.5 * (p[k] + p[k].transpose());
      if (in.keep_gains) out.gain[a][k] = c;
    }
    for (std::size_t k = 0; k < n; ++k) {
      out.dx_um[k][a] = e[k][0];
      out.dv_um_s[k][a] = e[k][1];
      out.bias_um_s2[k][a] = e[k][2];
      out.sigma_x_um[k][a] = std::sqrt(std::max(p[k](0, 0), 0.0));
      if (in.keep_gains) out.p_smoothed[a][k] = p[k];
    }
  }
  return out;
}

}  // namespace eical::dsp::fusion
