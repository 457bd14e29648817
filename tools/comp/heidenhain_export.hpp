#pragma once
// HEIDENHAIN nonlinear axis error compensation (TNC 640 / MANUALplus 620 NC software),
// from the HEIDENHAIN Technical Manual MANUALplus 620, "Entering compensation values" and
// "Assigning the compensation value tables to the axes" (pp. 716-718), and the error
// convention of the earlier TNC technical manuals (TNC 407/415/425 §1.6.3-1.6.4: "the
// axis-error is entered with the correct sign ... positive if the table travel is too
// long"; the compensation table holds the points of the error curve):
// * one table <axis>.COM per compensated axis: column AXISPOS the compensation points
//   (mm, from the machine datum), the column named after the axis (CfgAxes/axisList) the
//   error measured in the positive direction, column BACKLASH "the compensation values
//   measured in the negative direction of traverse";
// * a table CONFIG.CMA assigns them: one column per compensated axis holding its .COM
//   file (X = F(X): X.COM in column X), the line marked * in ACTIVE is in effect.
// eical writes deviation = actual − nominal (mm) in both, the error-curve convention.
// Not from the documentation at hand: the table files' frame (a "BEGIN <name> MM" line, a
// header line, "[END]") and the column widths follow how the TNC stores its tables;
// check by loading them into the table editor. Backlash alone (no table): machine
// parameter MP_backLash (p. 708), listed in heidenhain/backlash.txt.
#include "tools/comp/proposal.hpp"

#include <string>
#include <vector>

namespace eical::tools::comp {

struct HeidenhainOptions {
  GridOptions grid;
};

std::vector<OutputFile> heidenhain_outputs(const std::vector<AxisProposal>& axes, const HeidenhainOptions& o);

}  // namespace eical::tools::comp
