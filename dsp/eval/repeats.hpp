#pragma once
// Repeat segmentation by the NC's triggers and averaging of N repeats (6-44).
//
// A calibration program marks every repeat with M102 (before each revolution, before each
// pass of a step or a rectangle). The stretches between consecutive marks whose set-point
// paths coincide — relative to where each begins, within one sample of motion — are
// repeats of one segment. The deviation measured − commanded is averaged sample by sample
// across them: the noise falls as 1/√N while the machine's systematic deviation stays,
// and the spread across them is the repeatability (what the thesis quotes as scatter).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace eical::dsp::eval {

struct RepeatGroup {
  std::vector<std::int64_t> first_index;  // sample index where each repeat begins
  std::size_t samples = 0;                // common length
  std::vector<Eigen::Vector3d> mean_deviation_um;  // per sample of the segment
  std::vector<Eigen::Vector3d> spread_um;          // sample standard deviation across the repeats
  bool axis_moves[3] = {false, false, false};  // the set-point moves along it in the segment
  double scatter_rms_um = 0.0;   // RMS over the segment of the spread, over the moving axes
  double mean_rms_um = 0.0;      // RMS of the mean deviation, over the moving axes
  [[nodiscard]] int repeats() const noexcept { return static_cast<int>(first_index.size()); }
};

struct RepeatInput {
  const std::vector<std::int64_t>* sample_index = nullptr;
  const std::vector<Eigen::Vector3d>* pos_mm = nullptr;  // measured
  const std::vector<Eigen::Vector3d>* cmd_mm = nullptr;  // commanded
  std::vector<std::int64_t> marks;                        // M102 sample indices
  double fs_hz = 10000.0;
};

// Groups of at least two repeats, largest first. Segments that are not contiguous in the
// trace (lost frames) or not covered by it are left out.
std::vector<RepeatGroup> average_repeats(const RepeatInput& in);

}  // namespace eical::dsp::eval
