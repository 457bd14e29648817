#pragma once
// Whether an integrated motion is a position: something must hold the double integral —
// a rest before the motion (its bias), a standstill after it (ZUPT) or a PSD fix.
// run-format.md, "No standstill": a sweep or a machining cycle that moves from the first to
// the last sample has none; its double integral over minutes is no position error.
#include "dsp/pipeline/pipeline.hpp"

#include <string>

namespace eical::dsp {

inline constexpr double kMinRestS = 0.05;  // shortest rest before the motion that fixes a bias

// Why the integrated motion of `m` is no position (empty: it is one).
std::string unsupported_integration(const Measurement& m);

}  // namespace eical::dsp
