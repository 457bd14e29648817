#pragma once
// Calibration NC programs as ISO G-code with the measurement M-functions in place:
//   M101  program start: the machine rests; tare (bias reference) and start recording
//   M102  segment mark: a repeat starts, a corner or a target is reached
//   M103  program end: the machine rests again; stop recording and evaluate
// Every program begins and ends with a rest long enough for the bias and ZUPT windows.
// The text is what `eical gen-nc` prints and what the simulator runs.
#include "dsp/core/run_meta.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::sim::gcode {

struct RestTimes {
  double before_start_s = 0.4;  // G4 before M101 (the sample runs' convention)
  double after_start_s = 0.1;   // G4 between M101 and the first move
  double before_end_s = 0.4;    // G4 after the last move, before M103
  double after_end_s = 0.1;     // G4 after M103
};

// Circle (ISO 230-4): start at 45° on the circle, a quarter-arc ramp-in, `repeats` full
// revolutions each preceded by M102, a M102 after the last one, a quarter-arc ramp-out;
// G64 so that the arcs blend into one move at constant feed. Planes xy, zx, yz.
// direction "both": the ccw revolutions, a rest, then the cw revolutions back.
// Partial arc (arc_deg < 360, at most 340): ramp-in arc (min(45°, (360° − arc)/2)), M102,
// the evaluated arc from arc_start_deg (default 90° − arc/2: symmetric about the plane's
// second axis), M102, ramp-out arc; "both" comes back clockwise after a rest.
std::string circle_program(const dsp::Program& p, const RestTimes& rest = {});

// Where a partial arc begins (deg) and how long its ramps are (deg).
double partial_arc_start_deg(const dsp::Program& p);
double partial_arc_ramp_deg(const dsp::Program& p);

// ISO 230-2 linear positioning cycle: `runs` bidirectional runs over `targets_mm`
// (ascending), each target approached in both directions, with an overrun of
// `overrun_mm` beyond the end targets so that every approach of a direction is made the
// same way; dwell `dwell_s` and M102 at every target. G61 exact stop.
std::string positioning_program(const dsp::Program& p, double overrun_mm = 2.0, const RestTimes& rest = {});

// Step test: a rapid approach to targets_mm[0], then back and forth between the targets
// `runs` times, M102 at every arrival.
std::string step_program(const dsp::Program& p, const RestTimes& rest = {});

// Rectangle: corner_mm, size_mm in the program plane, counter-clockwise, M102 at every
// corner, `repeats` times. G61.
std::string rectangle_program(const dsp::Program& p, const RestTimes& rest = {});

// On-site identification (ch. 8.2 without a KGM). For every PSD strip: the spot is put
// on the strip's cross line and swung along the strip through its centre, both ways, at
// rising feeds (velocities for the damping term, accelerations for the scale and the
// cross-axis terms); for every further axis (e.g. z, which no strip measures) the same
// swings from where it is, seen by the set-point at the rests only. Every move ends in a
// dwell (ZUPT, and the set-point as a position at rest) and M102. Exact stop.
// A travel set for x or y keeps every swing along that axis inside it where the travel is
// at least the swing: its centre moves off the strip's centre as far as it must, so that
// the identification moves the axes only where the test that follows moves them. A travel
// shorter than the swing (a R10 circle) keeps the swing, the scale's lever, centred on the
// travel: a shorter swing identified the scale worse than the plan predicted (PlanCheck,
// rectangle 40 x 30 mm: U 1.55 x the repeats' spread).
struct AxisTravel {
  double lo_mm = 0.0, hi_mm = 0.0;
};
struct IdentifyPlan {
  std::vector<dsp::PsdSpec> psd;
  std::vector<std::string> axes;  // swung without a strip
  double swing_mm = 50.0;         // peak to peak (the scale's lever)
  std::vector<double> feeds_mm_min = {2000.0, 4000.0, 6500.0};
  double dwell_s = 0.5;                         // the position loop settles, then ZUPT
  std::optional<AxisTravel> travel_mm[2] = {};  // x, y: where the swings must stay
};
// Where the swing across `strip` goes along the axis it measures: its centre and half
// length (the travel applied).
struct Swing {
  double centre_mm = 0.0, half_mm = 0.0;
};
Swing strip_swing(const IdentifyPlan& plan, const dsp::PsdSpec& strip);
std::string identify_program(const IdentifyPlan& plan, const RestTimes& rest = {});
// The Program form (kind "identify"): one strip along `axis` centred at targets_mm[0],
// swing size_mm[0] (default 50 mm).
std::string identify_program(const dsp::Program& p, const RestTimes& rest = {});

// Dispatches on p.kind; throws InputError for an unknown or incomplete program.
std::string program_gcode(const dsp::Program& p);

}  // namespace eical::sim::gcode
