#pragma once
// One axis' compensation table and eical's single sign convention, shared by every export
// (CSV, JSON, LinuxCNC, SINUMERIK, FANUC, HEIDENHAIN):
//
//   deviation  = actual − nominal          (results.md, ISO 230-2: measured − commanded)
//   correction = −deviation                what the control must add to the commanded
//                                          position for the axis to arrive at nominal
//
// A table holds deviations; each export converts them once, with its control's documented
// meaning (tools/comp/). Tests apply every exported table back to the deviation it came
// from and get zero.
//
// Direction: forward = the axis approaches a position moving in + (ISO 230-2 x̄i↑),
// reverse = moving in − (x̄i↓). A play b between motor and slide (lost motion) makes the
// slide lag the motor: an approach in + stops b/2 short of the mean, one in − b/2 beyond
// it, so forward − reverse = −b (ISO 230-2 B of a pure play is −b).
#include <string>
#include <vector>

namespace eical::dsp::comp {

enum class Approach { forward, reverse };

inline constexpr double correction_from_deviation_um(double deviation_um) noexcept { return -deviation_um; }

struct AxisTable {
  int axis = 0;                    // 0 x, 1 y, 2 z
  std::vector<double> pos_mm;      // strictly increasing nominal positions
  std::vector<double> forward_um;  // deviation, approached in +
  std::vector<double> reverse_um;  // deviation, approached in −

  // Linear interpolation between points; beyond the ends the end value is held (what
  // LinuxCNC and the SINUMERIK tables do; a table is checked to cover the travel first).
  [[nodiscard]] double deviation_um(double at_mm, Approach a) const;
  [[nodiscard]] double correction_um(double at_mm, Approach a) const {
    return correction_from_deviation_um(deviation_um(at_mm, a));
  }
  [[nodiscard]] double mean_um(std::size_t i) const { return 0.5 * (forward_um[i] + reverse_um[i]); }
  // Mean of reverse − forward over the points: the lost motion b (positive for a play).
  [[nodiscard]] double mean_lost_motion_um() const;
  [[nodiscard]] double first_mm() const { return pos_mm.front(); }
  [[nodiscard]] double last_mm() const { return pos_mm.back(); }
};

// "x", "y", "z" for 0, 1, 2.
char axis_letter(int axis) noexcept;

// At least 2 points, same sizes, finite, strictly increasing: InputError naming the axis
// and the point otherwise.
void validate(const AxisTable& t);

// Both directions from a bidirectional mean and a constant lost motion b (the play folded
// in): forward = mean − b/2, reverse = mean + b/2.
AxisTable fold_lost_motion(int axis, const std::vector<double>& pos_mm, const std::vector<double>& mean_um,
                           double lost_motion_um);

// Both directions replaced by their mean (the reversal left out).
AxisTable without_reversal(const AxisTable& t);

// The table on an equidistant grid first + k·spacing, k = 0 … points − 1 (the controls
// whose tables have a fixed interval). InputError when the grid leaves the table's range:
// eical never extrapolates a measurement.
AxisTable resample(const AxisTable& t, double first_mm, double spacing_mm, int points);

// InputError when [from, to] is not inside the table's range, naming what needs it:
// "comp: the x table covers 0 .. 40 mm; circle run c1 measured x from -10 to 10 mm".
void require_coverage(const AxisTable& t, double from_mm, double to_mm, const std::string& who);

// Largest |deviation + correction applied by `applied`| over t's points and both
// directions, in µm: what is left of t's deviations when a control applies the table
// `applied` (the round-trip check every export is tested with).
double residual_after_um(const AxisTable& t, const AxisTable& applied);

}  // namespace eical::dsp::comp
