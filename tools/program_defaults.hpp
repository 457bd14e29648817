#pragma once
// Each test program's defaults, in one place for every command that builds one: a test
// planned with the defaults (`eical plan`) is the one `eical gen-nc` writes with them.
// Circle: the thesis' circular test (R10 F2500, 5 revolutions); positioning: ISO 230-2's
// 5 bidirectional runs; step: there and back twice at the feed of the thesis' step test.
#include <string_view>

namespace eical::tools::program_defaults {

inline constexpr double kCircleRadiusMm = 10.0;
inline constexpr double kCircleFeedMmMin = 2500.0;
inline constexpr int kCircleRevolutions = 5;
inline constexpr double kPositioningFeedMmMin = 2000.0;
inline constexpr int kPositioningRuns = 5;
inline constexpr double kStepFeedMmMin = 3250.0;
inline constexpr int kStepPairs = 2;
inline constexpr double kRectangleFeedMmMin = 1000.0;
inline constexpr int kRectangleLaps = 1;

// The feed of a program kind (circle, positioning, step, rectangle); 0 for another kind.
constexpr double feed_mm_min(dsp::ProgramKind kind) {
  if (kind == dsp::ProgramKind::circle) return kCircleFeedMmMin;
  if (kind == dsp::ProgramKind::positioning) return kPositioningFeedMmMin;
  if (kind == dsp::ProgramKind::step) return kStepFeedMmMin;
  if (kind == dsp::ProgramKind::rectangle) return kRectangleFeedMmMin;
  return 0.0;
}

// Positioning runs or step pairs (what --runs counts for that kind).
constexpr int runs(dsp::ProgramKind kind) { return kind == dsp::ProgramKind::step ? kStepPairs : kPositioningRuns; }

// Circle revolutions or rectangle laps (what --repeats counts for that kind).
constexpr int repeats(dsp::ProgramKind kind) {
  return kind == dsp::ProgramKind::rectangle ? kRectangleLaps : kCircleRevolutions;
}

}  // namespace eical::tools::program_defaults
