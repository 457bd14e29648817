#include "dsp/comp/volumetric_fit.hpp"

#include "dsp/comp/lincomp.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace eical::dsp::comp {
namespace {

constexpr int kTx = 0;  // index of axis a's translation in direction c: 6a + c
constexpr int kRx = 3;  // its rotations: 6a + 3 + c

std::string letter(int a) { return std::string(1, "xyz"[a]); }

// The frame (ISO 230-1 practice): x's motion defines the x axis, with y's motion the xy
// plane. Turning the sensors' frame by ω to get there changes a run's slopes by ω × axis;
// with ω fixed by xty, xtz and ytz having no slope, the squareness of a pair is the sum
// of the slopes (µm/mm) the two runs show in each other's channel:
//   xwy = −(s_y→x + s_x→y),  ywz = −(s_z→y + s_y→z),  xwz = s_z→x + s_x→z   (· 1e3 → µrad)
// (e_x = … − xwy·y + xwz·z, e_y = … − ywz·z; E_R of volumetric.hpp).
struct Pair {
  int a, b;  // the pair's two axes: the slope of b's run in a's channel and of a's run in b's
  double sign;
};
constexpr Pair kPairs[3] = {{0, 1, -1.0}, {1, 2, -1.0}, {0, 2, +1.0}};  // xwy, ywz, xwz

struct Channel {
  std::vector<double> pos_mm, value_um, u_um;  // standard uncertainty
};

// Per target of the moving axis: bidirectional mean of the channel over all stops. Its
// uncertainty: the pooled scatter of single stops about their target-and-direction mean
// (type A, over the runs) and the smoother's σ there, which repeating the run does not
// average away (type B).
Channel channel_of(const AxisPass& p, int c) {
  std::map<long long, std::array<std::vector<double>, 2>> by_target;  // 1 µm keys; [up, down]
  std::map<long long, std::pair<double, int>> sigma;                  // Σσ², count
  for (const auto& s : p.stops) {
    if (s.approach[p.axis] == 0) continue;
    const long long key = std::llround(s.cmd_mm[p.axis] * 1000.0);
    by_target[key][s.approach[p.axis] > 0 ? 0 : 1].push_back(s.dev_um[c]);
    sigma[key].first += s.sigma_um[c] * s.sigma_um[c], sigma[key].second += 1;
  }
  double ss = 0.0;
  int dof = 0;
  for (const auto& [k, dirs] : by_target)
    for (const auto& v : dirs) {
      if (v.size() < 2) continue;
      double m = 0.0;
      for (double x : v) m += x;
      m /= static_cast<double>(v.size());
      for (double x : v) ss += (x - m) * (x - m);
      dof += static_cast<int>(v.size()) - 1;
    }
  if (dof < 1)
    throw InputError("volumetric: the " + letter(p.axis) + " run " + p.source +
                     " has no target reached twice from one side: no scatter, no uncertainty");
  const double s = std::sqrt(ss / dof);
  Channel ch;
  for (const auto& [k, dirs] : by_target) {
    double sum = 0.0, var = 0.0;
    int n_dir = 0;
    for (const auto& v : dirs) {
      if (v.empty()) continue;
      double m = 0.0;
      for (double x : v) m += x;
      sum += m / static_cast<double>(v.size());
      var += s * s / static_cast<double>(v.size());
      ++n_dir;
    }
    ch.pos_mm.push_back(static_cast<double>(k) / 1000.0);
    ch.value_um.push_back(sum / n_dir);
    const double type_b2 = sigma[k].second > 0 ? sigma[k].first / sigma[k].second : 0.0;
    ch.u_um.push_back(std::sqrt(var / (n_dir * n_dir) + type_b2));
  }
  return ch;
}

struct Line {
  double slope = 0.0, intercept = 0.0, u_slope = 0.0;  // µm/mm, standard uncertainty
};
Line weighted_line(const Channel& ch) {
  double sw = 0, sx = 0, sy = 0;
  for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) {
    const double w = 1.0 / std::max(ch.u_um[i] * ch.u_um[i], 1e-12);
    sw += w, sx += w * ch.pos_mm[i], sy += w * ch.value_um[i];
  }
  const double xm = sx / sw, ym = sy / sw;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) {
    const double w = 1.0 / std::max(ch.u_um[i] * ch.u_um[i], 1e-12);
    sxx += w * (ch.pos_mm[i] - xm) * (ch.pos_mm[i] - xm), sxy += w * (ch.pos_mm[i] - xm) * (ch.value_um[i] - ym);
  }
  Line l;
  l.slope = sxx > 0 ? sxy / sxx : 0.0;
  l.intercept = ym - l.slope * xm;
  l.u_slope = sxx > 0 ? std::sqrt(1.0 / sxx) : 0.0;
  return l;
}

double reference_of(const std::array<double, 2>& range) { return range[0] <= 0.0 && 0.0 <= range[1] ? 0.0 : range[0]; }

using MergedRuns = std::array<std::optional<AxisPass>, 3>;  // per axis: all its positioning runs as one

// Every axis' runs merged into one; the range of each axis no run moved (where it stood,
// on average) into range_mm. Throws when no axis moved.
MergedRuns merge_runs(const std::vector<AxisPass>& passes, std::array<std::array<double, 2>, 3>& range_mm) {
  std::array<std::vector<const AxisPass*>, 3> by_axis;
  for (const auto& p : passes) by_axis[static_cast<std::size_t>(p.axis)].push_back(&p);
  // Ranges: a moved axis over its targets; a standing one where it stood.
  std::array<double, 3> still_sum{}, still_n{};
  for (const auto& p : passes)
    for (const auto& s : p.stops)
      for (int a = 0; a < 3; ++a)
        if (a != p.axis)
          still_sum[static_cast<std::size_t>(a)] += s.cmd_mm[a], still_n[static_cast<std::size_t>(a)] += 1.0;
  MergedRuns merged;
  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    if (by_axis[ai].empty()) {
      const double at = still_n[ai] > 0 ? still_sum[ai] / still_n[ai] : 0.0;
      range_mm[ai] = {at, at};
      continue;
    }
    AxisPass m;
    m.axis = a;
    for (const auto* p : by_axis[ai]) {
      m.source += (m.source.empty() ? "" : " + ") + p->source;
      m.stops.insert(m.stops.end(), p->stops.begin(), p->stops.end());
    }
    merged[ai] = m;
  }
  if (!merged[0] && !merged[1] && !merged[2]) throw InputError("volumetric: no positioning run to fit the model from");
  return merged;
}

using Slopes = std::array<std::array<std::optional<Line>, 3>, 3>;  // [moving axis][channel]

// The translation component of the run's axis a in direction c (positioning for c = a,
// straightness less its slope, which goes to `slope`, otherwise), relative to the machine at
// the axis' reference point, with its U; the axis' range from the run's targets.
void fit_translation(const AxisPass& run, int c, VolumetricFit& f, Slopes& slope) {
  const int a = run.axis;
  const auto ai = static_cast<std::size_t>(a);
  const int k = 6 * a + kTx + c;
  auto& comp = f.component[static_cast<std::size_t>(k)];
  Channel ch = channel_of(run, c);
  if (ch.pos_mm.size() < 2)
    throw InputError("volumetric: the " + letter(a) + " run " + run.source + " reached fewer than 2 targets");
  f.model.range_mm[ai] = {ch.pos_mm.front(), ch.pos_mm.back()};
  std::string note = "positioning run " + run.source + ", channel " + letter(c);
  if (c != a) {
    // A straightness has no slope: that is the frame and the squareness (kPairs).
    const Line l = weighted_line(ch);
    slope[ai][static_cast<std::size_t>(c)] = l;
    for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) ch.value_um[i] -= l.slope * ch.pos_mm[i] + l.intercept;
    note += " less its slope (frame and squareness)";
  }
  // Relative to the machine at the reference point of the axis.
  const double r = reference_of(f.model.range_mm[ai]);
  const double v_r = interpolate(ch.pos_mm, ch.value_um, r), u_r = interpolate(ch.pos_mm, ch.u_um, r);
  comp.u_k2.clear();
  for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) {
    ch.value_um[i] -= v_r;
    const bool at_ref = std::abs(ch.pos_mm[i] - r) < 1e-9;
    comp.u_k2.push_back(at_ref ? 0.0 : 2.0 * std::hypot(ch.u_um[i], u_r));
  }
  f.model.component[static_cast<std::size_t>(k)] = {ch.pos_mm, ch.value_um};
  comp.observed = true;
  comp.note = note;
}

using SquarenessEstimates = std::array<std::vector<std::pair<double, double>>, 3>;  // (µrad, U) per slot

// Each pair's squareness from the slopes of its two runs (kPairs), and from the circles in
// its plane that carry an uncertainty.
SquarenessEstimates squareness_estimates(const Slopes& slope, const std::vector<SquarenessFigure>& circles) {
  SquarenessEstimates square_est;
  for (std::size_t sl = 0; sl < 3; ++sl) {
    const auto a = static_cast<std::size_t>(kPairs[sl].a), b = static_cast<std::size_t>(kPairs[sl].b);
    const auto& ba = slope[b][a];  // b's run seen in a's channel
    const auto& ab = slope[a][b];
    if (ba && ab)
      square_est[sl].emplace_back(kPairs[sl].sign * (ba->slope + ab->slope) * 1e3,
                                  2.0 * std::hypot(ba->u_slope, ab->u_slope) * 1e3);
  }
  for (const auto& c : circles) {
    const auto slot = static_cast<std::size_t>(c.pair);
    // Ballbar convention (angle between the plane's +u and +v above 90° positive): xy → xwy,
    // yz → ywz; zx (u = z, v = x): xwz has the opposite sense (e_x = + xwz·z).
    const double value = c.pair == 2 ? -c.urad : c.urad;
    if (c.u_k2_urad && *c.u_k2_urad > 0.0) square_est[slot].emplace_back(value, *c.u_k2_urad);
  }
  return square_est;
}

// Each squareness the inverse-variance mean of its estimates; not observed without any.
void combine_squareness(const SquarenessEstimates& square_est, VolumetricFit& f) {
  const char* names[3] = {"xwy", "ywz", "xwz"};
  double* values[3] = {&f.model.xwy_urad, &f.model.ywz_urad, &f.model.xwz_urad};
  for (std::size_t s = 0; s < 3; ++s) {
    auto& sq = f.squareness[s];
    if (square_est[s].empty()) {
      sq.note = std::string(names[s]) +
                ": not observed (needs positioning runs of both axes of the pair, or a circle in its plane with an "
                "uncertainty)";
      continue;
    }
    double sw = 0.0, swv = 0.0;
    for (const auto& [v, u] : square_est[s]) {
      const double w = 1.0 / std::max(u * u, 1e-12);
      sw += w, swv += w * v;
    }
    *values[s] = swv / sw;
    sq.u_k2_urad = std::sqrt(1.0 / sw);
    sq.observed = true;
    sq.note = std::to_string(square_est[s].size()) + " estimate(s), inverse-variance mean";
  }
}

// What eical cannot observe, and the axes no run moved: zero over the axis' range, and why.
void mark_unobserved(VolumetricFit& f) {
  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    for (int k = 6 * a; k < 6 * a + 6; ++k) {
      auto& comp = f.component[static_cast<std::size_t>(k)];
      if (comp.observed) continue;
      const auto& rg = f.model.range_mm[ai];
      f.model.component[static_cast<std::size_t>(k)] =
          rg[0] < rg[1] ? SupportTable{{rg[0], rg[1]}, {0.0, 0.0}} : SupportTable{{rg[0]}, {0.0}};
      comp.note = k >= 6 * a + kRx ? "not observable: a rotation of the carriage moves eical's one measuring point "
                                     "like a translation; it needs a "
                                     "second measuring point at a known lever or an angle reference"
                                   : "not measured: no positioning run moves " + letter(a);
    }
  }
}

}  // namespace

VolumetricFit fit_volumetric(const std::vector<AxisPass>& passes, const std::vector<SquarenessFigure>& circles) {
  VolumetricFit f;
  const MergedRuns merged = merge_runs(passes, f.model.range_mm);
  Slopes slope;
  for (int a = 0; a < 3; ++a)
    if (merged[static_cast<std::size_t>(a)])
      for (int c = 0; c < 3; ++c) fit_translation(*merged[static_cast<std::size_t>(a)], c, f, slope);
  combine_squareness(squareness_estimates(slope, circles), f);
  mark_unobserved(f);
  return f;
}

Eigen::Vector3d prediction_u_k2(const VolumetricFit& fit, const Eigen::Vector3d& x_mm) {
  Eigen::Vector3d u2 = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) {
      const auto k = static_cast<std::size_t>(6 * a + kTx + c);
      if (!fit.component[k].observed) continue;
      const double u = interpolate(fit.model.component[k].pos_mm, fit.component[k].u_k2, x_mm[a]);
      u2[c] += u * u;
    }
  Eigen::Vector3d r;
  for (int a = 0; a < 3; ++a) r[a] = reference_of(fit.model.range_mm[static_cast<std::size_t>(a)]);
  // Squareness terms (µrad · mm = nm): e_x −xwy·y and +xwz·z, e_y −ywz·z.
  auto add = [&](int channel, std::size_t slot, int lever_axis) {
    if (!fit.squareness[slot].observed) return;
    const double u = fit.squareness[slot].u_k2_urad * std::abs(x_mm[lever_axis] - r[lever_axis]) * 1e-3;
    u2[channel] += u * u;
  };
  add(0, 0, 1);
  add(1, 1, 2);
  add(0, 2, 2);
  return u2.cwiseSqrt();
}

}  // namespace eical::dsp::comp
