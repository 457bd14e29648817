#pragma once
// quality.verdict of a result (verdict_kind.hpp):
//   not_measurable  the uncertainty of the program's limited figure exceeds what the test
//                   is meant to resolve (program_descriptor.hpp), or nothing holds the position;
//   degraded        a quality flag (lost frames, saturation, the strips disagreeing, ...);
//   ok              otherwise.
// The figures are given in every case, with their uncertainty. A figure below its own U is
// a result, not a failure of the measurement: |truth| <= |value| + U (k = 2) bounds it, and
// a good machine measured well has exactly such figures. Whether a figure meets a
// tolerance is a separate decision, ISO 14253-1's (conformance.hpp).
//
// What each program is meant to resolve (docs/uncertainty.md, "Verdict"): a circular test is a
// ballbar-class test of G, a positioning test an interferometer-class test of A, a step
// test resolves end positions to a few µm, a rectangle its corners, a free form its
// contour.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/program_descriptor.hpp"

#include <string>
#include <vector>

namespace eical::dsp {

// What the program must resolve (its row of program_descriptor.cpp); null: nothing.
const ResolutionLimit* resolution_limit(ProgramKind program);

// Sets a.verdict and a.verdict_reasons from the figures, their uncertainty and the flags.
void judge(const Program& program, Analysis& a);

}  // namespace eical::dsp
