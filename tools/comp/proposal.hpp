#pragma once
// What `eical comp` proposes per machine axis, in eical's sign convention
// (dsp/comp/axis_table.hpp), and the files an export turns it into.
#include "dsp/comp/axis_table.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::tools::comp {

struct AxisProposal {
  int axis = 0;
  // Deviation table over the measured positions, the reversal folded into its two
  // directions; or, without a positioning run, only the lost motion b (backlash).
  std::optional<dsp::comp::AxisTable> table;
  std::optional<double> lost_motion_um;
  std::string source;  // which runs and figures it comes from (for the files' comments)
};

struct OutputFile {
  std::string path;  // relative to the output folder
  std::string text;
};

// Equidistant grid options of the controls whose tables have a fixed interval.
struct GridOptions {
  double spacing_mm = 0.0;  // 0: the positioning run's mean target spacing
};

// The mean target spacing of a table (its range over its intervals), or `requested`.
double grid_spacing_mm(const dsp::comp::AxisTable& t, const GridOptions& o);

// The table on the equidistant grid from its first to its last position whose step is the
// largest not above the grid spacing.
dsp::comp::AxisTable equidistant(const dsp::comp::AxisTable& t, const GridOptions& o);

}  // namespace eical::tools::comp
