#pragma once
// One recorded run → everything eical can say about it: the pipeline over all frames,
// then the evaluation its program calls for. Used by `eical analyze`, `eical demo` and
// eicald (which evaluates every measurement it records), so all three agree by
// construction. An evaluation that cannot be done leaves its result empty and says why
// in `flags`; it does not throw.
#include "dsp/core/run.hpp"
#include "dsp/eval/circle.hpp"
#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/eval/step_response.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::dsp {

struct AnalysisOptions {
  DynamicComp dynamic = DynamicComp::two_stage;
  bool zupt = true;
};

struct Analysis {
  Measurement measurement;
  std::optional<eval::CircleResult> circle;
  std::optional<eval::CircleResult> circle_reference;  // the same evaluation of the reference channel
  std::optional<double> circle_accuracy_rms_um;        // RMS of (measured − reference) radius deviation
  std::optional<eval::CircleDiagnostics> diagnostics;
  std::optional<eval::StepResult> step;
  std::string step_axis;
  bool degraded = false;
  std::vector<std::string> flags;  // pipeline quality flags and evaluation failures
};

// Throws InputError only when the run itself is unusable (no frames, fs ≤ 0).
Analysis analyze_run(const Run& run, const AnalysisOptions& options = {});

// Plane axes of a program ("xy" → 0, 1; "zx" → 2, 0; "yz" → 1, 2).
std::pair<int, int> plane_axes(const std::string& plane);

}  // namespace eical::dsp
