#pragma once
// Piecewise-linear axis compensation (seed 002, HEIDENHAIN's procedure for its LIDA 400
// specification): correction points every A mm, linear interpolation between them. The
// residual after correction depends on where the grid of points lies, so the grid is
// shifted in steps (default 1 mm) over one spacing and the worst residual over all
// shifts is reported; the total adds the error within one signal period:
//   F_total = F_rest + u
// Every grid also has a point at each end of the travel (a table covers the whole axis);
// beyond the table the control holds the end value (LinuxCNC does), never extrapolates.
#include <vector>

namespace eical::dsp::comp {

struct ErrorCurve {
  std::vector<double> pos_mm;    // strictly increasing
  std::vector<double> error_um;  // measured − nominal
};

struct LinCompOptions {
  double spacing_mm = 50.0;
  double shift_step_mm = 1.0;
  double period_error_um = 0.0;  // u: position error within one signal period (magnitude)
};

struct CorrectionTable {
  std::vector<double> pos_mm;
  std::vector<double> deviation_um;  // the curve's deviation at each point (a control applies −deviation)
};

struct LinCompResult {
  double spacing_mm = 0.0;
  double max_residual_um = 0.0;  // F_rest: worst over all grid shifts
  double worst_shift_mm = 0.0;
  double total_um = 0.0;  // F_rest + u
  double residual_unshifted_um = 0.0;
  CorrectionTable table;                     // grid starting at the first curve position (shift 0)
  std::vector<double> residual_by_shift_um;  // per shift, for the report
};

// Tables and grid shifts no machine needs (a 50 m axis at 0.5 mm spacing; a 1 µm shift
// step at 10 mm spacing): beyond these the computation runs for hours, on a curve whose
// positions are not in millimetres, so it is refused. The longest machine axes (gantry
// mills) are a few tens of metres; each shift recomputes the whole table, so the product
// of table points and shifts is bounded too (a second's work; fuzzing found a 3.6 km
// curve that took minutes under the sanitizers).
inline constexpr int kMaxCorrectionPoints = 100000;
inline constexpr int kMaxGridShifts = 10000;
inline constexpr double kMaxTravelMm = 100000.0;
inline constexpr double kMaxTableEvaluations = 2e6;  // table points × grid shifts

// Validates the curve (monotone, finite, no duplicates, a travel up to kMaxTravelMm,
// spacing within it, at most kMaxCorrectionPoints points, kMaxGridShifts shifts and
// kMaxTableEvaluations of both) with InputError naming the offending point or figure.
LinCompResult piecewise_linear(const ErrorCurve& curve, const LinCompOptions& options);

// Correction table of a grid starting at `first_mm`, spacing A, over the curve's range.
CorrectionTable correction_table(const ErrorCurve& curve, double first_mm, double spacing_mm);
// Linear interpolation of a table (held constant beyond its ends).
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at);
// Max |error − correction| over the curve's points.
double max_residual_um(const ErrorCurve& curve, const CorrectionTable& table);

}  // namespace eical::dsp::comp
