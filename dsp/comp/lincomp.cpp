#include "dsp/comp/lincomp.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace eical::dsp::comp {

double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (x.empty()) return 0.0;
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const auto it = std::upper_bound(x.begin(), x.end(), at);
  const auto i = static_cast<std::size_t>(it - x.begin());
  const double u = (at - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + u * (y[i] - y[i - 1]);
}

CorrectionTable correction_table(const ErrorCurve& c, double first_mm, double spacing_mm) {
  CorrectionTable t;
  const double end = c.pos_mm.back();
  // Points at first + k·A inside the measured range (1e-9 mm tolerance for rounding).
  auto add = [&](double q) {
    if (!t.pos_mm.empty() && q <= t.pos_mm.back() + 1e-9) return;
    t.pos_mm.push_back(q);
    t.deviation_um.push_back(interpolate(c.pos_mm, c.error_um, q));
  };
  // Both ends of the travel always carry a point (a table covers the whole axis); the
  // grid points first + k·A lie in between.
  add(c.pos_mm.front());
  for (int k = 0;; ++k) {
    const double p = first_mm + k * spacing_mm;  // no accumulated rounding
    if (p > end + 1e-9) break;
    add(std::min(p, end));
  }
  add(end);
  return t;
}

double max_residual_um(const ErrorCurve& c, const CorrectionTable& t) {
  double worst = 0.0;
  for (std::size_t i = 0; i < c.pos_mm.size(); ++i)
    worst = std::max(worst, std::abs(c.error_um[i] - interpolate(t.pos_mm, t.deviation_um, c.pos_mm[i])));
  return worst;
}

LinCompResult piecewise_linear(const ErrorCurve& c, const LinCompOptions& o) {
  if (c.pos_mm.size() != c.error_um.size()) throw InputError("lincomp: positions and errors differ in count");
  if (c.pos_mm.size() < 2) throw InputError("lincomp: the error curve needs at least 2 points");
  for (std::size_t i = 0; i < c.pos_mm.size(); ++i) {
    if (!std::isfinite(c.pos_mm[i]) || !std::isfinite(c.error_um[i]))
      throw InputError("lincomp: point " + std::to_string(i + 1) + " is not a finite number");
    if (i > 0 && c.pos_mm[i] == c.pos_mm[i - 1])
      throw InputError("lincomp: duplicate position " + std::to_string(c.pos_mm[i]) + " mm (point " +
                       std::to_string(i + 1) + ")");
    if (i > 0 && c.pos_mm[i] < c.pos_mm[i - 1])
      throw InputError("lincomp: positions must increase; point " + std::to_string(i + 1) + " (" +
                       std::to_string(c.pos_mm[i]) + " mm) comes after " + std::to_string(c.pos_mm[i - 1]) + " mm");
  }
  const double travel = c.pos_mm.back() - c.pos_mm.front();
  if (!(o.spacing_mm > 0.0)) throw InputError("lincomp: spacing must be positive");
  if (o.spacing_mm > travel)
    throw InputError("lincomp: spacing " + std::to_string(o.spacing_mm) + " mm is larger than the travel " +
                     std::to_string(travel) + " mm");
  if (!(o.shift_step_mm > 0.0) || o.shift_step_mm > o.spacing_mm)
    throw InputError("lincomp: shift step must be in (0, spacing]");
  if (travel / o.spacing_mm + 1.0 > kMaxCorrectionPoints)
    throw InputError("lincomp: the travel " + std::to_string(travel) + " mm at spacing " +
                     std::to_string(o.spacing_mm) + " mm needs more than " + std::to_string(kMaxCorrectionPoints) +
                     " correction points (positions in mm?)");
  if (o.spacing_mm / o.shift_step_mm > kMaxGridShifts)
    throw InputError("lincomp: spacing " + std::to_string(o.spacing_mm) + " mm / shift step " +
                     std::to_string(o.shift_step_mm) + " mm is more than " + std::to_string(kMaxGridShifts) +
                     " grid shifts");
  if (!(o.period_error_um >= 0.0)) throw InputError("lincomp: period error u must not be negative");

  LinCompResult r;
  r.spacing_mm = o.spacing_mm;
  const double x0 = c.pos_mm.front();
  r.table = correction_table(c, x0, o.spacing_mm);
  r.residual_unshifted_um = max_residual_um(c, r.table);
  const auto n_shifts = static_cast<int>(std::floor(o.spacing_mm / o.shift_step_mm + 1e-9));
  r.max_residual_um = -1.0;
  for (int k = 0; k < n_shifts; ++k) {
    const double shift = k * o.shift_step_mm;
    // The shifted grid: points at x0 + shift + n·A inside the travel, plus its ends.
    const CorrectionTable t = correction_table(c, x0 + shift, o.spacing_mm);
    const double res = max_residual_um(c, t);
    r.residual_by_shift_um.push_back(res);
    if (res > r.max_residual_um) r.max_residual_um = res, r.worst_shift_mm = shift;
  }
  r.total_um = r.max_residual_um + o.period_error_um;
  return r;
}

}  // namespace eical::dsp::comp
