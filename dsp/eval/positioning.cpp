#include "dsp/eval/positioning.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::eval {

PositioningResult evaluate_positioning(const PositioningInput& input) {
  const std::size_t m = input.targets_mm.size();
  if (m < 2) throw InputError("ISO 230-2: at least 2 targets are needed");
  if (input.up_um.size() < 2 || input.down_um.size() < 2)
    throw InputError("ISO 230-2: at least 2 runs per direction are needed");
  if (input.up_um.size() != input.down_um.size())
    throw InputError("ISO 230-2: the two directions have different numbers of runs");
  for (const auto* dir : {&input.up_um, &input.down_um})
    for (std::size_t j = 0; j < dir->size(); ++j) {
      if ((*dir)[j].size() != m)
        throw InputError("ISO 230-2: run " + std::to_string(j + 1) + (dir == &input.up_um ? " up" : " down") + " has " +
                         std::to_string((*dir)[j].size()) + " deviations for " + std::to_string(m) + " targets");
      for (double v : (*dir)[j])
        if (!std::isfinite(v))
          throw InputError("ISO 230-2: run " + std::to_string(j + 1) + " holds a non-finite deviation");
    }
  const auto n = static_cast<double>(input.up_um.size());
  PositioningResult r;
  r.axis = input.axis;
  r.runs = static_cast<int>(input.up_um.size());
  auto stats = [&](const std::vector<std::vector<double>>& d, std::size_t i, double& mean, double& s) {
    mean = 0.0;
    for (const auto& run : d) mean += run[i];
    mean /= n;
    double ss = 0.0;
    for (const auto& run : d) ss += (run[i] - mean) * (run[i] - mean);
    s = std::sqrt(ss / (n - 1.0));
  };
  double hi_up = -kInf, lo_up = kInf, hi_dn = -kInf, lo_dn = kInf;      // x̄ ± 2s
  double max_mu = -kInf, min_mu = kInf, max_md = -kInf, min_md = kInf;  // x̄↑, x̄↓
  double max_m = -kInf, min_m = kInf;                                   // x̄i
  double vdi_hi = -kInf, vdi_lo = kInf;
  double sum_b = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    PositioningTarget t;
    t.target_mm = input.targets_mm[i];
    stats(input.up_um, i, t.mean_up_um, t.s_up_um);
    stats(input.down_um, i, t.mean_down_um, t.s_down_um);
    t.mean_um = 0.5 * (t.mean_up_um + t.mean_down_um);
    t.B_um = t.mean_up_um - t.mean_down_um;
    t.R_up_um = 4.0 * t.s_up_um;
    t.R_down_um = 4.0 * t.s_down_um;
    t.R_um = std::max({2.0 * t.s_up_um + 2.0 * t.s_down_um + std::abs(t.B_um), t.R_up_um, t.R_down_um});
    hi_up = std::max(hi_up, t.mean_up_um + 2 * t.s_up_um), lo_up = std::min(lo_up, t.mean_up_um - 2 * t.s_up_um);
    hi_dn = std::max(hi_dn, t.mean_down_um + 2 * t.s_down_um),
    lo_dn = std::min(lo_dn, t.mean_down_um - 2 * t.s_down_um);
    max_mu = std::max(max_mu, t.mean_up_um), min_mu = std::min(min_mu, t.mean_up_um);
    max_md = std::max(max_md, t.mean_down_um), min_md = std::min(min_md, t.mean_down_um);
    max_m = std::max(max_m, t.mean_um), min_m = std::min(min_m, t.mean_um);
    r.R_up_um = std::max(r.R_up_um, t.R_up_um);
    r.R_down_um = std::max(r.R_down_um, t.R_down_um);
    r.R_um = std::max(r.R_um, t.R_um);
    r.B_um = std::max(r.B_um, std::abs(t.B_um));
    sum_b += t.B_um;
    // VDI/DGQ 3441: U_i = |x̄i↑ − x̄i↓|, Ps_i = 6·s̄_i with s̄_i the mean of both directions.
    const double Ui = std::abs(t.B_um), Psi = 6.0 * 0.5 * (t.s_up_um + t.s_down_um);
    r.vdi.U_um = std::max(r.vdi.U_um, Ui);
    r.vdi.Ps_um = std::max(r.vdi.Ps_um, Psi);
    vdi_hi = std::max(vdi_hi, t.mean_um + 0.5 * (Ui + Psi));
    vdi_lo = std::min(vdi_lo, t.mean_um - 0.5 * (Ui + Psi));
    r.targets.push_back(t);
  }
  r.B_mean_um = sum_b / static_cast<double>(m);
  r.A_up_um = hi_up - lo_up;
  r.A_down_um = hi_dn - lo_dn;
  r.A_um = std::max(hi_up, hi_dn) - std::min(lo_up, lo_dn);
  r.E_up_um = max_mu - min_mu;
  r.E_down_um = max_md - min_md;
  r.E_um = std::max(max_mu, max_md) - std::min(min_mu, min_md);
  r.M_um = max_m - min_m;
  r.vdi.Pa_um = max_m - min_m;
  r.vdi.P_um = vdi_hi - vdi_lo;
  return r;
}

std::array<NamedFigure, 12> iso230_2_figures(const PositioningResult& r) {
  return {{{"A_um", r.A_um},
           {"A_up_um", r.A_up_um},
           {"A_down_um", r.A_down_um},
           {"E_um", r.E_um},
           {"E_up_um", r.E_up_um},
           {"E_down_um", r.E_down_um},
           {"M_um", r.M_um},
           {"R_um", r.R_um},
           {"R_up_um", r.R_up_um},
           {"R_down_um", r.R_down_um},
           {"B_um", r.B_um},
           {"B_mean_um", r.B_mean_um}}};
}

std::array<NamedFigure, 4> vdi3441_figures(const Vdi3441& v) {
  return {{{"P_um", v.P_um}, {"Pa_um", v.Pa_um}, {"U_um", v.U_um}, {"Ps_um", v.Ps_um}}};
}

}  // namespace eical::dsp::eval
