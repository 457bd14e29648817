#pragma once
// Stick-slip: at low feed static friction holds the slide until its lag breaks it free, and
// it jumps forward in a few milliseconds, again and again. Each slip is a burst of relative
// acceleration far above the sensors' noise (a micrometre in 2 ms is ~3 m/s²), many of
// them while an axis creeps (its set-point slower than 10 mm/s but moving: the quadrant
// changes of a circle, the ends of every ramp). One burst per reversal is backlash taking
// up its play; a train of them at creep speed is stick-slip. Where the axis has a
// reference, the slips' size is the sawtooth the reference shows against the set-point.
#include "dsp/model/run_residuals.hpp"

#include <string>

namespace eical::dsp::model {

struct StickSlipFinding {
  bool found = false;
  int axis = -1;  // the axis with the most bursts per creep zone
  int creep_zones = 0, bursts_in_creep = 0, bursts_elsewhere = 0;
  double bursts_per_zone = 0.0;  // median over the zones of that axis
  double creep_seconds = 0.0, other_seconds = 0.0;
  double slip_um = 0.0;  // sawtooth size from the reference (0 without one)
  std::string evidence;
};

StickSlipFinding stick_slip_test(const RunResiduals& run);

// Where axis `axis` creeps (its set-point slower than stick-slip's creep speed, but moving),
// the set-point's direction there (+1, −1), per decimated sample of `run`; 0 elsewhere.
// The slide sticks behind its set-point and slips forward, so reference − set-point lags
// by about half the sawtooth against this direction (the reference's creep-lag column).
Eigen::VectorXd creep_direction(const RunResiduals& run, int axis);

}  // namespace eical::dsp::model
