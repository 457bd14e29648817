#pragma once
// A simulated run as another system would have recorded it (`eical simulate --export`),
// so that the importers are tested end to end on a known truth:
//  * the capture: one sensor's samples taken at jittered times (the simulator's
//    JitteredCapture, sim/regimes/capture_clock), decoded with the run's data sheet to
//    m/s² with its [site] g (raw: bias and gravity stay in, as in a Klipper capture),
//    stamped on the capture clock,
//    lost batches left out;
//  * the NC trace: the set-point at the servo rate on the NC's clock, t_nc = t + nc_offset_s.
#include "drivers/import/capture_files.hpp"
#include "dsp/core/run.hpp"
#include "sim/nc/set_point.hpp"
#include "sim/regimes/capture_clock.hpp"
#include "sim/simulate.hpp"

namespace eical::drivers {

// `part`: the sensor recorded (0 table, 1 head).
StampedAccel exported_capture(const dsp::Run& run, const sim::JitteredCapture& jittered,
                              const sim::CaptureSamples& samples, const sim::CaptureClock& clock, int part,
                              const std::string& source);

// Sample numbers N on the servo grid (t_nc = N·period) covering the set-point's duration.
NcTrace exported_nc_trace(const sim::nc::SetPoint& set_point, double period_s, double nc_offset_s,
                          const std::string& source);

}  // namespace eical::drivers
