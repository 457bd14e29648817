#pragma once
// What the channels' health (dsp/health) means for a program's figures. The relative
// acceleration head − table of a machine axis takes every sensor axis that to_machine maps
// onto it (both sensors); the program needs the axes of its plane (circle, rectangle, free
// form), its one axis (step, positioning) or all three. A channel those axes need that does
// not measure (empty, stuck, dead) leaves the program's figures unevaluated — absent, with
// the reason — never millimetres integrated from a flat line. The pipeline holds a whole
// sensor while a field of it is missing (and both at full scale): an empty column spoils
// its sensor's axes, a missing or clipped span degrades the result, as does a PSD
// electrode with any finding (its strip's fixes are suspect) and a recording cut short.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/health/channel_health.hpp"

#include <vector>

namespace eical::dsp {

// Machine axes (bit i: X, Y, Z) the program's figures are made of.
unsigned program_axes(const Program& program);
// Machine axes accel channel c (0..5) contributes to (to_machine; none for other channels).
unsigned channel_axes(const RunMeta& meta, int c);

// Flags each finding (channel_untrusted, channel_unused, truncated); a.degraded when one
// limits the result. False when the program's figures must not be evaluated (a needed
// channel does not measure): an evaluation_failed flag on the program then says why.
bool judge_channels(const RunMeta& meta, const std::vector<health::Finding>& findings, Analysis& a);

}  // namespace eical::dsp
