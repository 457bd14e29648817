#pragma once
// The per-program evaluations analyze_run() dispatches to (one file each). Each fills its
// part of the Analysis or leaves it empty and adds the reason to `flags`; none throws.
#include "dsp/analysis/analyze_run.hpp"

namespace eical::dsp::detail {

void evaluate_circle_program(const Run& run, Analysis& a, const EvaluationOptions& options);
void evaluate_rectangle_program(const Run& run, Analysis& a);
void evaluate_freeform_program(const Run& run, Analysis& a);

}  // namespace eical::dsp::detail
