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

CorrectionTable correction_table(const ErrorCurve& curve, double first_mm, double spacing_mm) {
  CorrectionTable t;
  const double end = curve.pos_mm.back();
  // Points at first + k·A inside the measured range (1e-9 mm tolerance for rounding).
  auto add = [&](double q) {
    if (!t.pos_mm.empty() && q <= t.pos_mm.back() + 1e-9) return;
    t.pos_mm.push_back(q);
    t.deviation_um.push_back(interpolate(curve.pos_mm, curve.error_um, q));
  };
  // Both ends of the travel always carry a point (a table covers the whole axis); the
  // grid points first + k·A lie in between.
  add(curve.pos_mm.front());
  for (int k = 0;; ++k) {
    const double p = first_mm + k * spacing_mm;  // no accumulated rounding
    if (p > end + 1e-9) break;
    add(std::min(p, end));
  }
  add(end);
  return t;
}

double max_residual_um(const ErrorCurve& curve, const CorrectionTable& table) {
  double worst = 0.0;
  for (std::size_t i = 0; i < curve.pos_mm.size(); ++i)
    worst =
        std::max(worst, std::abs(curve.error_um[i] - interpolate(table.pos_mm, table.deviation_um, curve.pos_mm[i])));
  return worst;
}

LinCompResult piecewise_linear(const ErrorCurve& curve, const LinCompOptions& options) {
  if (curve.pos_mm.size() != curve.error_um.size()) throw InputError("lincomp: positions and errors differ in count");
  if (curve.pos_mm.size() < 2) throw InputError("lincomp: the error curve needs at least 2 points");
  for (std::size_t i = 0; i < curve.pos_mm.size(); ++i) {
    if (!std::isfinite(curve.pos_mm[i]) || !std::isfinite(curve.error_um[i]))
      throw InputError("lincomp: point " + std::to_string(i + 1) + " is not a finite number");
    if (i > 0 && curve.pos_mm[i] == curve.pos_mm[i - 1])
      throw InputError("lincomp: duplicate position " + std::to_string(curve.pos_mm[i]) + " mm (point " +
                       std::to_string(i + 1) + ")");
    if (i > 0 && curve.pos_mm[i] < curve.pos_mm[i - 1])
      throw InputError("lincomp: positions must increase; point " + std::to_string(i + 1) + " (" +
                       std::to_string(curve.pos_mm[i]) + " mm) comes after " + std::to_string(curve.pos_mm[i - 1]) +
                       " mm");
  }
  const double travel = curve.pos_mm.back() - curve.pos_mm.front();
  if (travel > kMaxTravelMm)
    throw InputError("lincomp: the curve spans " + std::to_string(travel) + " mm, more than the " +
                     std::to_string(static_cast<int>(kMaxTravelMm / 1000.0)) +
                     " m of any machine axis (positions in mm?)");
  if (!(options.spacing_mm > 0.0)) throw InputError("lincomp: spacing must be positive");
  if (options.spacing_mm > travel)
    throw InputError("lincomp: spacing " + std::to_string(options.spacing_mm) + " mm is larger than the travel " +
                     std::to_string(travel) + " mm");
  if (!(options.shift_step_mm > 0.0) || options.shift_step_mm > options.spacing_mm)
    throw InputError("lincomp: shift step must be in (0, spacing]");
  if (travel / options.spacing_mm + 1.0 > kMaxCorrectionPoints)
    throw InputError("lincomp: the travel " + std::to_string(travel) + " mm at spacing " +
                     std::to_string(options.spacing_mm) + " mm needs more than " +
                     std::to_string(kMaxCorrectionPoints) + " correction points (positions in mm?)");
  if (options.spacing_mm / options.shift_step_mm > kMaxGridShifts)
    throw InputError("lincomp: spacing " + std::to_string(options.spacing_mm) + " mm / shift step " +
                     std::to_string(options.shift_step_mm) + " mm is more than " + std::to_string(kMaxGridShifts) +
                     " grid shifts");
  if ((travel / options.spacing_mm + 1.0) * (options.spacing_mm / options.shift_step_mm) > kMaxTableEvaluations)
    throw InputError("lincomp: " + std::to_string(travel / options.spacing_mm + 1.0) + " correction points times " +
                     std::to_string(options.spacing_mm / options.shift_step_mm) + " grid shifts is more than " +
                     std::to_string(kMaxTableEvaluations) + " table evaluations: a coarser shift step or spacing");
  if (!(options.period_error_um >= 0.0)) throw InputError("lincomp: period error u must not be negative");

  LinCompResult r;
  r.spacing_mm = options.spacing_mm;
  const double x0 = curve.pos_mm.front();
  r.table = correction_table(curve, x0, options.spacing_mm);
  r.residual_unshifted_um = max_residual_um(curve, r.table);
  const auto n_shifts = static_cast<int>(std::floor(options.spacing_mm / options.shift_step_mm + 1e-9));
  r.max_residual_um = -1.0;
  for (int k = 0; k < n_shifts; ++k) {
    const double shift = k * options.shift_step_mm;
    // The shifted grid: points at x0 + shift + n·A inside the travel, plus its ends.
    const CorrectionTable t = correction_table(curve, x0 + shift, options.spacing_mm);
    const double res = max_residual_um(curve, t);
    r.residual_by_shift_um.push_back(res);
    if (res > r.max_residual_um) r.max_residual_um = res, r.worst_shift_mm = shift;
  }
  r.total_um = r.max_residual_um + options.period_error_um;
  return r;
}

}  // namespace eical::dsp::comp
