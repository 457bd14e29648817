#pragma once
// Step response and stick-slip evaluation of a single-axis move sequence (a cross-grid
// encoder's step-response test): each move of the set-point is found in the command
// trace itself (no triggers needed), and the measured position around it is judged.
#include <cstddef>
#include <string>
#include <vector>

namespace eical::dsp::eval {

struct StepOptions {
  double settle_band_um = 1.0;  // settled once |measured − target| stays inside this band
  double end_window_s = 0.1;    // end position = mean over the last part of the dwell
  double min_dwell_s = 0.05;    // a rest shorter than this is not a dwell
};

struct StepMove {
  std::size_t start = 0;   // first sample where the set-point moves
  std::size_t arrive = 0;  // first sample where it rests at the target
  std::size_t end = 0;     // one past the last sample of the dwell
  double from_mm = 0.0, to_mm = 0.0;
  double step_measured_um = 0.0;  // measured displacement end − before
  double end_error_um = 0.0;      // measured − commanded end position
  double overshoot_um = 0.0;      // largest excursion beyond the target, ≥ 0
  double settling_s = 0.0;        // from arrival until inside the band for good
  bool settled = false;           // false: never inside the band before the dwell ended
  bool resolved = false;          // measured step within 50 % of commanded and > 3σ noise
};

struct StepResult {
  std::vector<StepMove> moves;
  double end_position_error_um = 0.0;  // mean over moves
  double scatter_um = 0.0;             // std of end errors of moves to the same target and direction
  double overshoot_um = 0.0;           // largest over moves
  double settling_s = 0.0;             // largest over settled moves
  double noise_um = 0.0;               // std of the measured position in the dwell end windows
  double smallest_step_resolved_um =
      0.0;  // smallest commanded step such that it and all larger are resolved; 0 if none
};

// `cmd_mm` and `meas_mm` on one sample clock; throws InputError when they differ in
// length, hold non-finite values or contain no complete move.
StepResult evaluate_steps(const std::vector<double>& cmd_mm, const std::vector<double>& meas_mm, double fs_hz,
                          const StepOptions& options = {});

}  // namespace eical::dsp::eval
