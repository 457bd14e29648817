#include "dsp/fusion/bias_steps.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::fusion {
namespace {
// A jump is what one move does to the bias: standstills further apart than this hold a
// drift (the case warming, ch. 6.1.3) that the walk and the temperature terms carry, and a
// drift taken for a jump at every move would loosen the whole run.
constexpr double kMaxGapS = 5.0;
constexpr std::size_t kMinPairs = 3;  // fewer: the standard error is all there is
}  // namespace

BiasStepMeasurement measure_bias_step(const std::vector<StandstillMean>& standstills,
                                      const Eigen::Vector3d& start_bias_sigma_um_s2, double batch_var_um2_s4,
                                      std::size_t batch_dof, double batch_s, double model_noise_um_s2_rthz,
                                      double walk_um_s2_rts) {
  BiasStepMeasurement out;
  // A batch mean over batch_s of white noise of density² q has variance q / batch_s.
  const double q_a = batch_dof >= 5 && std::isfinite(batch_var_um2_s4)
                         ? batch_var_um2_s4 * batch_s
                         : model_noise_um_s2_rthz * model_noise_um_s2_rthz;
  out.noise_um_s2_rthz = std::sqrt(q_a);
  const double q_b = walk_um_s2_rts * walk_um_s2_rts;
  // Per pair and axis: d² and what noise and walk alone make of it; the neighbours' shared
  // standstill (its own variance) correlates their d².
  struct Term {
    double d2, expected, shared_var;
  };
  std::vector<Term> terms;
  double t_prev = 0.0;
  Eigen::Vector3d mean_prev = Eigen::Vector3d::Zero();
  Eigen::Vector3d var_prev = start_bias_sigma_um_s2.cwiseAbs2();
  bool shared = false;  // the previous pair's later standstill is this pair's earlier one
  for (const StandstillMean& s : standstills) {
    if (!(s.length_s > 0.0) || !s.mean_um_s2.allFinite() || !(s.t_s >= t_prev)) continue;
    const Eigen::Vector3d d = s.mean_um_s2 - mean_prev;
    const double own_var = q_a / s.length_s;
    if (s.t_s - t_prev <= kMaxGapS) {
      for (int a = 0; a < 3; ++a)
        terms.push_back({d[a] * d[a], var_prev[a] + own_var + q_b * (s.t_s - t_prev), shared ? var_prev[a] : 0.0});
      ++out.pairs;
    }
    shared = s.t_s - t_prev <= kMaxGapS;  // for the next pair: this standstill's mean is in both
    t_prev = s.t_s, mean_prev = s.mean_um_s2, var_prev = Eigen::Vector3d::Constant(own_var);
  }
  if (out.pairs < kMinPairs) return out;
  const auto m = static_cast<double>(terms.size());
  double excess = 0.0;
  for (const Term& t : terms) excess += t.d2 - t.expected;
  out.measured = true;
  out.excess_um2_s4 = excess / m;
  // Its standard error with the jumps as found: Var(d²) = 2·E[d²]², and neighbours add
  // 2·Cov(d₁², d₂²) = 4·Var(shared)².
  const double step2 = std::max(0.0, out.excess_um2_s4);
  double spread = 0.0;
  for (const Term& t : terms) {
    const double e = t.expected + step2;
    spread += 2.0 * e * e + 4.0 * t.shared_var * t.shared_var;
  }
  out.step_um_s2 = std::sqrt(step2 + std::sqrt(spread) / m);
  return out;
}

}  // namespace eical::dsp::fusion
