#pragma once
// The decision of ISO 14253-1 for a figure against its tolerance, given its expanded
// uncertainty U (k = 2), as a type; conformance.hpp decides it.
#include <cstdint>
#include <string>
#include <vector>

namespace eical::dsp {

enum class Conformance : std::uint8_t {
  conforming,     // |value| + U <= tolerance: conformance proven
  nonconforming,  // |value| − U > tolerance: non-conformance proven
  undecided,      // the uncertainty zone straddles the tolerance (or U is unknown)
};

// JSON names ("conforming", ...) and the words a report uses ("conformance proven", ...).
[[nodiscard]] const char* conformance_key(Conformance c) noexcept;
[[nodiscard]] const char* conformance_words(Conformance c) noexcept;

// One toleranced figure of a run.
struct FigureConformance {
  std::string name;        // "circular deviation G (ISO 230-4)"
  std::string key;         // the result key compared (figures.hpp)
  double magnitude = 0.0;  // |value|, in the figure's unit
  double u_k2 = 0.0;       // NaN when unknown (then never proven either way)
  double tolerance = 0.0;  // upper limit of |value|
  Conformance decision = Conformance::undecided;
};

struct ConformanceResult {
  std::vector<FigureConformance> figures;
  // Non-conformance proven when any figure's is; conformance proven when every figure's
  // is; undecided otherwise (also when no toleranced figure could be evaluated).
  Conformance overall = Conformance::undecided;
};

}  // namespace eical::dsp
