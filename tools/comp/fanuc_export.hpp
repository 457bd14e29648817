#pragma once
// FANUC pitch error compensation and backlash.
// Documented (FANUC Series 0i-PB Parameter Manual B-63980EN/01, parameters 3620-3624;
// FANUC Series 15i/150i-MODEL A Parameter Manual B-63330EN/03, §3 "Inputting and
// outputting parameters using external input/output devices"):
// * No. 3620 number of the compensation point of the reference position, 3621 of the
//   farthest point in the negative direction, 3622 in the positive direction, 3623
//   magnification, 3624 interval between points (per axis); "the compensation value is
//   output at the compensation position No. corresponding to each section between the
//   coordinates": each point carries the INCREMENT of the compensation over the section
//   that ends at it, the absolute compensation at the reference position is zero.
// * A parameter record begins and ends with "%"; an axis-type parameter is
//   "N<number>A<axis>P<value>" per axis (the record format of B-63330EN/03).
// Not found in the documentation at hand, so stated here rather than invented:
// * the sign: eical writes the compensation AMOUNT, i.e. what is added to the command
//   (correction = −deviation, as LinuxCNC's trims and Mitsubishi's documented "division
//   interval − actual movement"); verify with one point on the first machine;
// * the data numbers under which the compensation values themselves are punched, so they
//   are given as a table for the PITCH ERROR COMPENSATION screen, not as a tape record;
// * the permitted range of one value (series dependent): magnification 1, values in
//   detection units — check against the series' limit.
// Backlash: No. 1851 (backlash compensation value, detection units), the lost motion b.
// Point 3621 itself carries no section (it is the lower end) and is written 0.
#include "tools/comp/proposal.hpp"

#include <string>
#include <vector>

namespace eical::tools::comp {

struct FanucOptions {
  GridOptions grid;
  double detection_unit_um = 1.0;  // IS-B: 1 µm
  double reference_mm = 0.0;       // the reference position (machine coordinate of No. 3620)
  int first_point_number = 0;      // the first axis' lowest point number; later axes follow
};

std::vector<OutputFile> fanuc_outputs(const std::vector<AxisProposal>& axes, const FanucOptions& o);

}  // namespace eical::tools::comp
