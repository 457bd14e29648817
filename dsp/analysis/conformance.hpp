#pragma once
// ISO 14253-1 (decision rules for proving conformance or non-conformance with
// specifications): a figure conforms to an upper tolerance T when |value| + U <= T, does not
// conform when |value| − U > T, and the measurement cannot tell between. U is the figure's
// expanded uncertainty (k = 2) from the analysis; a figure without one is undecided.
#include "dsp/analysis/analyze_run.hpp"

#include <string>
#include <vector>

namespace eical::dsp {

// A tolerance on the magnitude of a figure, or on the largest magnitude of several (ISO
// 230-4's radial deviation F: the larger of |F max| and |F min|).
struct FigureTolerance {
  std::string name;               // as a reader reads it
  std::vector<std::string> keys;  // result keys (figures.hpp)
  double tolerance = 0.0;         // in the figures' unit
};

[[nodiscard]] Conformance decide(double magnitude, double u_k2, double tolerance) noexcept;

// Every tolerance whose figure the analysis has; the others are left out (a circle's
// tolerance on a positioning run says nothing).
ConformanceResult decide_conformance(const Analysis& a, const std::vector<FigureTolerance>& tolerances);

}  // namespace eical::dsp
