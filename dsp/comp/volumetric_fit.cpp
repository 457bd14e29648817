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

double reference_of(const std::array<double, 2>& range) { return range[0] <= 0.0 && 0.0 <= range[1] ? 0.0 : range[0]; }

// Per target of the moving axis (1 µm keys), the bidirectional mean of channel c: the mean
// of the two directions' means (a backlash then adds half of itself everywhere, which the
// reference takes out). Targets reached from one side only are left out: their mean would
// carry half a reversal the others do not.
RunChannel bidirectional_means(int axis, const std::vector<Standstill>& stops, int c) {
  std::map<long long, std::array<std::pair<double, int>, 2>> by_target;  // [up, down]: Σ, n
  for (const auto& s : stops) {
    if (s.approach[axis] == 0) continue;
    auto& d = by_target[std::llround(s.cmd_mm[axis] * 1000.0)][s.approach[axis] > 0 ? 0 : 1];
    d.first += s.dev_um[c], d.second += 1;
  }
  RunChannel ch;
  for (const auto& [key, dirs] : by_target) {
    if (dirs[0].second == 0 || dirs[1].second == 0) continue;
    ch.pos_mm.push_back(static_cast<double>(key) / 1000.0);
    ch.value_um.push_back(0.5 * (dirs[0].first / dirs[0].second + dirs[1].first / dirs[1].second));
  }
  return ch;
}

// The least-squares slope (µm/mm) and intercept; unweighted: every target's mean is as good
// as another's (the same stops, the same supports), and the draws re-fit the same line.
std::pair<double, double> least_squares_line(const RunChannel& ch) {
  const auto n = static_cast<double>(ch.pos_mm.size());
  double xm = 0.0, ym = 0.0;
  for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) xm += ch.pos_mm[i] / n, ym += ch.value_um[i] / n;
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < ch.pos_mm.size(); ++i)
    sxx += (ch.pos_mm[i] - xm) * (ch.pos_mm[i] - xm), sxy += (ch.pos_mm[i] - xm) * (ch.value_um[i] - ym);
  const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
  return {slope, ym - slope * xm};
}

using MergedRuns = std::array<std::optional<AxisPass>, 3>;  // per axis: its runs as one

// The runs of one axis as one: per target the mean of their values, and of their U — the
// runs share the sensor model and the strips, whose error averaging does not shrink (full
// correlation: the mean's U is at most the runs' mean U).
AxisPass merge_axis(const std::vector<const AxisPass*>& runs) {
  AxisPass m = *runs.front();
  const auto n = static_cast<double>(runs.size());
  for (std::size_t r = 1; r < runs.size(); ++r) {
    const AxisPass& p = *runs[r];
    m.source += " + " + p.source;
    for (std::size_t c = 0; c < 3; ++c)
      if (p.fit.channel[c].pos_mm != m.fit.channel[c].pos_mm)
        throw InputError("volumetric: the " + letter(m.axis) + " runs " + m.source +
                         " reached different targets: fit them apart or repeat the same cycle");
  }
  for (std::size_t c = 0; c < 3; ++c) {
    auto& ch = m.fit.channel[c];
    std::fill(ch.value_um.begin(), ch.value_um.end(), 0.0);
    std::fill(m.u_k2_um[c].begin(), m.u_k2_um[c].end(), 0.0);
    ch.slope_um_per_mm = m.slope_u_k2_um_per_mm[c] = 0.0;
    for (const AxisPass* p : runs) {
      for (std::size_t i = 0; i < ch.value_um.size(); ++i)
        ch.value_um[i] += p->fit.channel[c].value_um[i] / n, m.u_k2_um[c][i] += p->u_k2_um[c][i] / n;
      ch.slope_um_per_mm += p->fit.channel[c].slope_um_per_mm / n;
      m.slope_u_k2_um_per_mm[c] += p->slope_u_k2_um_per_mm[c] / n;
    }
  }
  return m;
}

// Every axis' runs merged into one; the range of each axis no run moved (where it stood,
// on average) into range_mm. Throws when no axis moved.
MergedRuns merge_runs(const std::vector<AxisPass>& passes, std::array<std::array<double, 2>, 3>& range_mm) {
  std::array<std::vector<const AxisPass*>, 3> by_axis;
  for (const auto& p : passes) {
    for (std::size_t c = 0; c < 3; ++c)
      if (p.u_k2_um[c].size() != p.fit.channel[c].pos_mm.size())
        throw InputError("volumetric: the run " + p.source + " has no uncertainty for its " + letter(int(c)) +
                         " channel");
    by_axis[static_cast<std::size_t>(p.axis)].push_back(&p);
  }
  MergedRuns merged;
  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    if (by_axis[ai].empty()) {  // an axis no run moved: where the runs stood
      double sum = 0.0;
      for (const auto& p : passes) sum += p.fit.standing_mm[ai];
      const double at = passes.empty() ? 0.0 : sum / static_cast<double>(passes.size());
      range_mm[ai] = {at, at};
      continue;
    }
    merged[ai] = merge_axis(by_axis[ai]);
  }
  if (!merged[0] && !merged[1] && !merged[2]) throw InputError("volumetric: no positioning run to fit the model from");
  return merged;
}

using Slopes = std::array<std::array<std::optional<std::pair<double, double>>, 3>, 3>;  // [axis][channel]: µm/mm, U

// The translation component of the run's axis a in direction c (positioning for c = a,
// straightness less its slope otherwise), its U per support, the axis' range.
void fit_translation(const AxisPass& run, int c, VolumetricFit& f, Slopes& slope) {
  const int a = run.axis;
  const auto ai = static_cast<std::size_t>(a), ci = static_cast<std::size_t>(c);
  auto& comp = f.component[static_cast<std::size_t>(6 * a + kTx + c)];
  const RunChannel& ch = run.fit.channel[ci];
  f.model.range_mm[ai] = {ch.pos_mm.front(), ch.pos_mm.back()};
  std::string note = "positioning run " + run.source + ", channel " + letter(c);
  if (c != a) {
    slope[ai][ci] = std::pair(ch.slope_um_per_mm, run.slope_u_k2_um_per_mm[ci]);
    note += " less its slope (frame and squareness)";
  }
  f.model.component[static_cast<std::size_t>(6 * a + kTx + c)] = {ch.pos_mm, ch.value_um};
  comp.u_k2 = run.u_k2_um[ci];
  comp.observed = true;
  comp.note = note + "; U from the run's draws";
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
      square_est[sl].emplace_back(kPairs[sl].sign * (ba->first + ab->first) * 1e3,
                                  std::hypot(ba->second, ab->second) * 1e3);
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

RunComponents run_components(int axis, const std::vector<Standstill>& stops) {
  RunComponents r;
  r.axis = axis;
  for (const auto& s : stops)
    for (int a = 0; a < 3; ++a)
      r.standing_mm[static_cast<std::size_t>(a)] += s.cmd_mm[a] / static_cast<double>(stops.size());
  for (int c = 0; c < 3; ++c) {
    RunChannel ch = bidirectional_means(axis, stops, c);
    if (ch.pos_mm.size() < 2)
      throw InputError("volumetric: the " + letter(axis) + " run reached fewer than 2 targets from both sides");
    if (c != axis) {
      // A straightness has no slope: that is the frame and the squareness (kPairs).
      const auto [slope, intercept] = least_squares_line(ch);
      ch.slope_um_per_mm = slope;
      for (std::size_t i = 0; i < ch.pos_mm.size(); ++i) ch.value_um[i] -= slope * ch.pos_mm[i] + intercept;
    }
    // Relative to the machine at the reference point of the axis.
    const double v_r = interpolate(ch.pos_mm, ch.value_um, reference_of({ch.pos_mm.front(), ch.pos_mm.back()}));
    for (double& v : ch.value_um) v -= v_r;
    r.channel[static_cast<std::size_t>(c)] = std::move(ch);
  }
  return r;
}

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
