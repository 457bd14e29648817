#include "sim/psd/psd_strip.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::sim {
namespace {

// Fraction of a Gaussian (σ) centred at 0 that falls within [lo, hi]; exact 0/1 far away.
double covered(double lo, double hi, double sigma) {
  const double k = 1.0 / (sigma * std::numbers::sqrt2);
  auto cdf = [&](double x) { return x < -8.0 * sigma ? 0.0 : (x > 8.0 * sigma ? 1.0 : 0.5 * std::erfc(-x * k)); };
  return cdf(hi) - cdf(lo);
}

}  // namespace

PsdStrip::PsdStrip(const dsp::PsdSpec& spec, const PsdTruth& truth, double step_s) : spec_(spec), truth_(truth) {
  if (spec.measures == "x")
    along_ = 0, across_ = 1;
  else if (spec.measures == "y")
    along_ = 1, across_ = 0;
  else
    throw dsp::InputError("psd: measures must be \"x\" or \"y\", got \"" + spec.measures + "\"");
  if (!(spec.length_mm > 0.0) || !(spec.width_mm > 0.0))
    throw dsp::InputError("psd: length_mm and width_mm must be positive");
  sigma_mm_ = std::max(truth.spot_mm, 1e-6) / 4.0;  // 1/e² diameter = 4σ
  alpha_ = spec.lockin_tau_s > 0.0 ? 1.0 - std::exp(-step_s / spec.lockin_tau_s) : 1.0;
  h_ = step_s;
}

void PsdStrip::step(const Eigen::Vector3d& rel_mm, double& i1_v, double& i2_v) noexcept {
  const double u = rel_mm[along_] - spec_.center_mm[along_];
  const double w = rel_mm[across_] - spec_.center_mm[across_];
  const double half_l = spec_.length_mm / 2.0, half_w = spec_.width_mm / 2.0;
  double target1 = 0.0, target2 = 0.0;
  // Most of the time the spot is far from the strip: the cross direction decides first.
  const double across = covered(-half_w - w, half_w - w, sigma_mm_);
  const double light = across > 0.0 ? across * covered(-half_l - u, half_l - u, sigma_mm_) : 0.0;
  if (light > 0.0) {
    const double uc = std::clamp(u, -half_l, half_l);
    const double r = 2.0 * uc / spec_.length_mm;
    const double um = uc * (1.0 + truth_.nonlinearity * r * r);
    target1 = light * truth_.full_scale_v * (0.5 + um / spec_.length_mm);
    target2 = light * truth_.full_scale_v * (0.5 - um / spec_.length_mm);
  }
  // The lock-in's first-order lag, exact for an input linear over the step (a ramp comes
  // out exactly τ late, as from the analogue filter): y ← a·y + x₁ − a·x₀ − τ·ṡ·(1 − a).
  const double a = 1.0 - alpha_;
  const double tau_slope1 = spec_.lockin_tau_s > 0.0 ? spec_.lockin_tau_s * (target1 - prev1_) / h_ : 0.0;
  const double tau_slope2 = spec_.lockin_tau_s > 0.0 ? spec_.lockin_tau_s * (target2 - prev2_) / h_ : 0.0;
  i1_ = a * i1_ + target1 - a * prev1_ - tau_slope1 * (1.0 - a);
  i2_ = a * i2_ + target2 - a * prev2_ - tau_slope2 * (1.0 - a);
  prev1_ = target1, prev2_ = target2;
  i1_v = i1_, i2_v = i2_;
}

}  // namespace eical::sim
