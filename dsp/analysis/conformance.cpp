#include "dsp/analysis/conformance.hpp"

#include "dsp/analysis/figures.hpp"

#include <cmath>
#include <limits>

namespace eical::dsp {

const char* conformance_key(Conformance c) noexcept {
  switch (c) {
    case Conformance::conforming: return "conforming";
    case Conformance::nonconforming: return "nonconforming";
    case Conformance::undecided: return "undecided";
  }
  return "undecided";
}

const char* conformance_words(Conformance c) noexcept {
  switch (c) {
    case Conformance::conforming: return "conformance proven";
    case Conformance::nonconforming: return "non-conformance proven";
    case Conformance::undecided: return "undecided";
  }
  return "undecided";
}

Conformance decide(double magnitude, double u_k2, double tolerance) noexcept {
  if (!std::isfinite(magnitude) || !std::isfinite(u_k2) || !(u_k2 >= 0.0)) return Conformance::undecided;
  if (magnitude + u_k2 <= tolerance) return Conformance::conforming;
  if (magnitude - u_k2 > tolerance) return Conformance::nonconforming;
  return Conformance::undecided;
}

ConformanceResult decide_conformance(const Analysis& a, const std::vector<FigureTolerance>& tolerances) {
  const std::vector<FigureValue> figs = figures_of(a);
  ConformanceResult r;
  for (const FigureTolerance& t : tolerances) {
    const FigureValue* worst = nullptr;
    for (const std::string& key : t.keys) {
      const FigureValue* f = find_figure(figs, key);
      if (!f || f->values.size() != 1 || !std::isfinite(f->values[0])) continue;
      if (!worst || std::abs(f->values[0]) > std::abs(worst->values[0])) worst = f;
    }
    if (!worst) continue;
    FigureConformance c;
    c.name = t.name, c.key = worst->key, c.tolerance = t.tolerance;
    c.magnitude = std::abs(worst->values[0]);
    const auto it = a.uncertainty_k2.find(worst->key);
    c.u_k2 = it != a.uncertainty_k2.end() && it->second.size() == 1 ? it->second[0]
                                                                    : std::numeric_limits<double>::quiet_NaN();
    c.decision = decide(c.magnitude, c.u_k2, c.tolerance);
    r.figures.push_back(c);
  }
  bool all = !r.figures.empty(), any_non = false;
  for (const auto& f : r.figures)
    all &= f.decision == Conformance::conforming, any_non |= f.decision == Conformance::nonconforming;
  r.overall = any_non ? Conformance::nonconforming : all ? Conformance::conforming : Conformance::undecided;
  return r;
}

}  // namespace eical::dsp
