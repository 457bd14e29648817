#pragma once
// The set-point of a program the NC ran, reconstructed by eical's interpolator and put on
// the DAQ clock (for an NC whose set-point eicald cannot read: it knows only the program
// and the M-function marks in the recording).
//
// Alignment, in two steps:
//  1 marks: the program's M101/M102/M103 times against the recorded trigger marks (in
//    order) give a coarse offset DAQ time − program time for each stretch; the marks carry
//    the trigger's latency (PLC, DDS: a few ms), the M-codes' dead time and the feed
//    override of the real NC;
//  2 cross-correlation: each motion block of the program (motion between two stops; the
//    set-point rests between blocks) is shifted by the lag that best matches commanded and
//    measured relative acceleration, searched within ±max_lag_s of the marks' offset.
// Between blocks the set-point rests, so a different offset per block never makes it jump.
// The lag found includes the machine's servo lag (the set-point is then aligned with the
// actual motion). The alignment's residual, RMS(measured − commanded acceleration) relative
// to RMS(commanded), says how well the reconstructed program matches what the NC did.
#include "dsp/core/flag.hpp"
#include "dsp/core/run.hpp"
#include "sim/nc/trajectory.hpp"

#include <string>
#include <vector>

namespace eical::drivers {

struct ProgramSetPointOptions {
  sim::nc::MachineLimits limits;  // the NC's path limits (acceleration, jerk, rapid)
  double max_lag_s = 0.3;         // cross-correlation search around the marks' offset
  // The NC stops at every M-code (LinuxCNC runs user M-codes queue-drained); eical's
  // interpolator blends through them unless told.
  bool mcode_stops = false;
  double poor_residual_ratio = 0.5;  // above this the result is flagged
};

struct BlockAlignment {
  double program_start_s = 0.0, program_end_s = 0.0;
  double marks_offset_s = 0.0;  // DAQ time − program time from the marks
  double offset_s = 0.0;        // after the cross-correlation
  double correlation = 0.0;
  bool correlated = false;  // false: the marks' offset kept (too little motion or no clear peak)
};

struct ProgramAlignment {
  std::vector<BlockAlignment> blocks;
  int marks_program = 0, marks_recorded = 0, marks_matched = 0;
  double lag_s = 0.0, correlation = 0.0, residual_ratio = 1.0;  // of the final set-point
  std::vector<dsp::Flag> flags;  // why the alignment is doubtful (FlagCode::setpoint; empty: fine)
};

// Fills every frame's cmd_mm from `program` (clearing cmd_missing) and sets
// run.meta.program. Throws dsp::InputError when the program cannot be interpolated or the
// recording has no M101 mark.
ProgramAlignment apply_program_setpoint(dsp::Run& run, const dsp::Program& program,
                                        const ProgramSetPointOptions& options);

// The G-code with a zero dwell after every M101/M102/M103 block: eical's interpolator then
// stops there, as an NC that drains its queue for user M-codes does.
std::string with_mcode_stops(const std::string& gcode);

}  // namespace eical::drivers
