#include "drivers/import/uniform_clock.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::drivers {
namespace {

// Least-squares line t = t0 + index/fs.
void fit_line(const std::vector<double>& t, UniformClock& c) {
  const double n = static_cast<double>(t.size());
  double mi = 0.0, mt = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) mi += static_cast<double>(c.index[k]), mt += t[k] - t.front();
  mi /= n, mt /= n;
  double sii = 0.0, sit = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double di = static_cast<double>(c.index[k]) - mi;
    sii += di * di, sit += di * (t[k] - t.front() - mt);
  }
  const double dt = sit / sii;
  c.fs_hz = 1.0 / dt;
  c.t0_s = t.front() + mt - dt * mi;
}

// A difference of more than 1.5·dt (the rounding boundary between one step and two) is a
// gap: one lost sample leaves 2·dt, which a threshold at 2·dt would miss half the time
// (jitter, or exact stamps a rounding error apart). Unless the sample was only late: then
// the difference after it is short by as much, and the two together span two steps.
bool is_gap(const std::vector<double>& t, std::size_t k, double dt) {
  const double d = t[k] - t[k - 1];
  if (!(d > 1.5 * dt)) return false;
  if (d > 2.5 * dt || k + 1 == t.size()) return true;
  return t[k + 1] - t[k - 1] > 2.5 * dt;
}

// Gaps may lose at most as many samples as the recording holds: a recording that is more
// gap than samples has stamps in another unit or is not one recording, and the importer
// would hold its whole grid in memory (a gap of 1e9 s at 1 kHz: 1e12 set-points).
void assign_indices(const std::vector<double>& t, double dt, UniformClock& c, const std::string& source) {
  c.index.assign(t.size(), 0);
  c.gaps = c.lost_frames = 0;
  const auto max_lost = static_cast<double>(t.size());
  for (std::size_t k = 1; k < t.size(); ++k) {
    const double d = t[k] - t[k - 1];
    std::int64_t step = 1;
    if (is_gap(t, k, dt)) {
      const double steps = d / dt;  // checked before it becomes an integer (and the indices add up)
      if (!(static_cast<double>(c.lost_frames) + steps - 1.0 <= max_lost))
        throw dsp::InputError(source + ": a gap of " + std::to_string(d) + " s after sample " + std::to_string(k) +
                              " loses more samples than the " + std::to_string(t.size()) +
                              " recorded (time stamps in another unit?)");
      step = std::max<std::int64_t>(2, std::llround(steps));
      ++c.gaps;
      c.lost_frames += static_cast<std::size_t>(step - 1);
    }
    c.index[k] = c.index[k - 1] + step;
  }
}

// Lagrange weights of the nodes x[0..m) at x.
Eigen::Vector3d lagrange(const double* x, const Eigen::Vector3d* y, int m, double at) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int i = 0; i < m; ++i) {
    double w = 1.0;
    for (int j = 0; j < m; ++j)
      if (j != i) w *= (at - x[j]) / (x[i] - x[j]);
    out += w * y[i];
  }
  return out;
}

// Four nodes around `at` within [lo, hi] (indices of one unbroken stretch), k the last
// node at or before `at`.
Eigen::Vector3d cubic_in(const std::vector<double>& t, const std::vector<Eigen::Vector3d>& v, std::size_t lo,
                         std::size_t hi, std::size_t k, double at) {
  const std::size_t len = hi - lo + 1;
  if (len == 1) return v[lo];
  const std::size_t m = std::min<std::size_t>(4, len);
  // Centre the window on [k, k+1]: nodes k−1 .. k+2, shifted into the stretch.
  std::size_t first = k >= lo + 1 ? k - 1 : lo;
  if (first + m - 1 > hi) first = hi - (m - 1);
  return lagrange(&t[first], &v[first], static_cast<int>(m), at);
}

}  // namespace

UniformClock fit_uniform_clock(const std::vector<double>& t_s, const std::string& source) {
  if (t_s.size() < 4)
    throw dsp::InputError(source + ": " + std::to_string(t_s.size()) + " samples; at least 4 are needed for a clock");
  std::vector<double> d(t_s.size() - 1);
  for (std::size_t k = 1; k < t_s.size(); ++k) {
    d[k - 1] = t_s[k] - t_s[k - 1];
    if (!(d[k - 1] > 0.0))
      throw dsp::InputError(source + ": time stamps do not increase at sample " + std::to_string(k + 1));
  }
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  UniformClock c;
  c.median_dt_s = d[d.size() / 2];
  assign_indices(t_s, c.median_dt_s, c, source);
  fit_line(t_s, c);
  assign_indices(t_s, 1.0 / c.fs_hz, c, source);  // gaps measured with the fitted rate
  fit_line(t_s, c);
  double s2 = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    const double r = t_s[k] - c.time_at(c.index[k]);
    s2 += r * r;
  }
  c.jitter_rms_s = std::sqrt(s2 / static_cast<double>(t_s.size()));
  return c;
}

UniformSeries resample(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values,
                       const UniformClock& clock) {
  if (t_s.size() != values.size() || t_s.size() != clock.index.size())
    throw dsp::InputError("resample: stamps, values and clock disagree in length");
  UniformSeries out;
  out.grid_index.reserve(t_s.size());
  out.values.reserve(t_s.size());
  // Unbroken stretches [lo, hi] between gaps; every sample's own grid point is produced.
  std::size_t lo = 0;
  while (lo < t_s.size()) {
    std::size_t hi = lo;
    while (hi + 1 < t_s.size() && clock.index[hi + 1] == clock.index[hi] + 1) ++hi;
    std::size_t k = lo;
    for (std::size_t s = lo; s <= hi; ++s) {
      const double at = clock.time_at(clock.index[s]);
      while (k < hi && t_s[k + 1] <= at) ++k;
      while (k > lo && t_s[k] > at) --k;
      out.grid_index.push_back(clock.index[s]);
      out.values.push_back(cubic_in(t_s, values, lo, hi, k, at));
    }
    lo = hi + 1;
  }
  return out;
}

std::vector<Eigen::Vector3d> bridge_gaps(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values,
                                         const UniformClock& clock) {
  const auto n = static_cast<std::size_t>(clock.index.back()) + 1;
  std::vector<Eigen::Vector3d> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = interpolate_at(t_s, values, clock.time_at(static_cast<std::int64_t>(i)));
  return out;
}

Eigen::Vector3d interpolate_at(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values, double at) {
  if (t_s.empty()) throw dsp::InputError("interpolate: no samples");
  if (at <= t_s.front()) return values.front();
  if (at >= t_s.back()) return values.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(t_s.begin(), t_s.end(), at) - t_s.begin()) - 1;
  return cubic_in(t_s, values, 0, t_s.size() - 1, k, at);
}

}  // namespace eical::drivers
