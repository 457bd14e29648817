#pragma once
// ISO 230-2:2014 accuracy and repeatability of positioning of a linear axis from
// bidirectional runs (the laser interferometer's test), and the VDI/DGQ 3441 figures.
// Deviation x_ij = measured − target at target i in run j (µm). Definitions (ISO 230-2
// clause 3): mean unidirectional deviation x̄i↑/↓, estimator of the standard uncertainty
// s_i↑/↓ (n − 1), reversal value B_i = x̄i↑ − x̄i↓, repeatability R_i↑/↓ = 4 s_i↑/↓,
// bidirectional R_i = max(2s_i↑ + 2s_i↓ + |B_i|, R_i↑, R_i↓); axis figures B = max|B_i|,
// B̄ = mean B_i, R = max R_i, E↑/↓ = max − min of x̄i↑/↓, E = max(x̄↑, x̄↓) − min(x̄↑, x̄↓),
// M = max x̄i − min x̄i (x̄i = (x̄i↑ + x̄i↓)/2), A↑/↓ = max(x̄ + 2s) − min(x̄ − 2s) per
// direction, A = the same over both directions.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace eical::dsp::eval {

// Runs per target and direction the standard asks for (ISO 230-2:2014, 4.3.2).
inline constexpr int kRunsPerTargetIso230_2 = 5;

struct PositioningInput {
  std::string axis = "x";
  std::vector<double> targets_mm;
  std::vector<std::vector<double>> up_um;    // [run][target]
  std::vector<std::vector<double>> down_um;  // [run][target]
  // The sample indices [first, last] each deviation averages (the dwells' second halves):
  // the only part of the path the figures read. Empty: not known (deviations imported).
  std::vector<std::pair<std::int64_t, std::int64_t>> read_sample_index;
};

struct PositioningTarget {
  double target_mm = 0.0;
  double mean_up_um = 0.0, mean_down_um = 0.0, mean_um = 0.0;
  double s_up_um = 0.0, s_down_um = 0.0;
  double B_um = 0.0, R_up_um = 0.0, R_down_um = 0.0, R_um = 0.0;
};

struct Vdi3441 {
  double P_um = 0.0;   // positioning uncertainty: max(x̄i + (U_i + Ps_i)/2) − min(x̄i − (U_i + Ps_i)/2)
  double Pa_um = 0.0;  // positional deviation: max x̄i − min x̄i
  double U_um = 0.0;   // max reversal span U_i = |x̄i↑ − x̄i↓|
  double Ps_um = 0.0;  // max position scatter Ps_i = 6·(s_i↑ + s_i↓)/2
};

struct PositioningResult {
  std::string axis;
  int runs = 0;
  std::vector<PositioningTarget> targets;
  double A_um = 0, A_up_um = 0, A_down_um = 0;
  double E_um = 0, E_up_um = 0, E_down_um = 0;
  double M_um = 0;
  double R_um = 0, R_up_um = 0, R_down_um = 0;
  double B_um = 0, B_mean_um = 0;
  Vdi3441 vdi;
};

// Throws InputError for fewer than 2 runs or 2 targets, ragged tables or NaN.
PositioningResult evaluate_positioning(const PositioningInput& input);

// The axis figures by the keys a result's "positioning" object names them ("A_um", …):
// the one list the result document, the figures of an analysis and their nulls read.
struct NamedFigure {
  const char* key;
  double value;
};
std::array<NamedFigure, 12> iso230_2_figures(const PositioningResult& r);
std::array<NamedFigure, 4> vdi3441_figures(const Vdi3441& v);  // keys of its own "vdi3441" object

}  // namespace eical::dsp::eval
