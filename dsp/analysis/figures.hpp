#pragma once
// Every numeric figure of an analysis under its result key `<section>.<key>`
// (docs/result-format.md): what `uncertainty_k2` gives an uncertainty for, and what the
// uncertainty's draws are compared on. Settings (nominal radius, feed, targets, the
// counts of revolutions and runs) are not figures; neither is a choice among discrete
// candidates (the cyclic error's pitch, the smallest step resolved).
//
// Arrays keep their result shape: a scalar has one value, an array (per target, per
// corner, per side) one per element, a table of pairs (corner errors x, y) `columns` = 2.
#include "dsp/analysis/analyze_run.hpp"

#include <string>
#include <vector>

namespace eical::dsp {

struct FigureValue {
  std::string key;             // "circle.circular_deviation_G_um"
  std::vector<double> values;  // one for a scalar
  bool array = false;
  int columns = 1;
};

// A rectangle's figures of the motion across its sides: what NBS, holding the other axis,
// assumes rather than measures (analyze_path.cpp), written and read under these keys.
inline constexpr const char* kRectangleStraightnessKey = "rectangle.sides.straightness_um";
inline constexpr const char* kRectangleDirectionKey = "rectangle.sides.direction_error_urad";
inline constexpr const char* kRectangleCornerAngleKey = "rectangle.corner_angle_error_urad";
inline constexpr const char* kRectangleAcrossSideKeys[] = {kRectangleStraightnessKey, kRectangleDirectionKey,
                                                           kRectangleCornerAngleKey};

std::vector<FigureValue> figures_of(const Analysis& analysis);

// The figure under `key`, or null.
const FigureValue* find_figure(const std::vector<FigureValue>& figures, const std::string& key);

// Scalar circle figure of one direction: max − min of its radius deviation (G per direction).
double direction_G_um(const eval::CircleResult& circle, const std::string& direction);

}  // namespace eical::dsp
