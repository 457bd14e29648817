#pragma once
// The per-program evaluations, one file each, registered in program_descriptor.cpp. Each
// fills its part of the Analysis or leaves it empty and adds the reason to `flags`; none
// throws.
#include "dsp/analysis/analyze_run.hpp"

namespace eical::dsp::detail {

void evaluate_circle_program(const Run& run, Analysis& a, const EvaluationOptions& options);
void evaluate_rectangle_program(const Run& run, Analysis& a, const EvaluationOptions& options);
void evaluate_freeform_program(const Run& run, Analysis& a, const EvaluationOptions& options);
void evaluate_step_program(const Run& run, Analysis& a, const EvaluationOptions& options);         // analyze_axis.cpp
void evaluate_positioning_program(const Run& run, Analysis& a, const EvaluationOptions& options);  // analyze_axis.cpp

}  // namespace eical::dsp::detail
