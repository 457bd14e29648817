#pragma once
// SINUMERIK 840D sl: measuring system error compensation (MSEC, of which the leadscrew
// error compensation LEC is part) and backlash, from SIEMENS "SINUMERIK 840D sl/828D
// Extended Functions, Function Manual 03/2013 (6FC5397-1BP40-3BA1), K3 Compensations":
// * §4.4.2.1: "The principle of the MSEC is to modify the axis-specific position actual
//   value by the assigned compensation value ... A positive compensation value causes the
//   corresponding machine axis to move in the negative direction." An axis that goes too
//   far (deviation > 0) is pulled back by a positive value: value = deviation.
// * §4.4.2.3 (example): the table is the part program %_N_AX_EEC_INI with CHANDATA(1),
//   $AA_ENC_COMP[0,N,<axis>] (mm) at equidistant interpolation points
//   $AA_ENC_COMP_STEP/_MIN/_MAX, $AA_ENC_COMP_IS_MODULO, closed by M17; the number of
//   points must not exceed MD38000 $MA_MM_ENC_COMP_MAX_POINTS. The table should be zero at
//   the reference point (§4.4.1): eical's values refer to the run's start instead, a
//   constant the reference point approach absorbs; shift the table if the jump matters.
// * One MSEC table serves both directions. The lost motion goes into MD32450
//   $MA_BACKLASH[0] (mm), "positive, if the encoder is leading the machine part (normal
//   situation)" (SINUMERIK 808D Advanced Parameter Manual 08/2013, 6FC5397-8EP40-0BA0,
//   MD32450), i.e. b of a play. Position-dependent reversal would need two
//   direction-dependent CEC tables ($AN_CEC_DIRECTION, K3 §4.4.3): not written — the
//   sign convention of CEC values was not found in the documentation at hand.
// Which direction of travel carries MD32450 after the reference point approach is not
// stated in the documentation found; the MSEC table holds the bidirectional mean, so the
// two directions differ by exactly b either way, up to a constant of b/2.
#include "tools/comp/proposal.hpp"

#include <string>
#include <vector>

namespace eical::tools::comp {

struct SinumerikOptions {
  GridOptions grid;
  std::vector<std::string> axis_names = {"X1", "Y1", "Z1"};  // machine axis names for x, y, z
};

std::vector<OutputFile> sinumerik_outputs(const std::vector<AxisProposal>& axes, const SinumerikOptions& o);

}  // namespace eical::tools::comp
