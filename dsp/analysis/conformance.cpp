#include "dsp/analysis/conformance.hpp"

#include "dsp/analysis/figures.hpp"

#include <cmath>
#include <limits>
#include <optional>

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
  // A tolerance over several figures (F: F max and F min) is decided by each, and the
  // figure that decides worst is reported: one undecided figure leaves the tolerance
  // undecided even when another, larger one conforms.
  const auto rank = [](Conformance c) {
    return c == Conformance::nonconforming ? 2 : c == Conformance::undecided ? 1 : 0;
  };
  for (const FigureTolerance& t : tolerances) {
    std::optional<FigureConformance> worst;
    for (const std::string& key : t.keys) {
      const FigureValue* f = find_figure(figs, key);
      if (!f || f->values.size() != 1 || !std::isfinite(f->values[0])) continue;
      FigureConformance c;
      c.name = t.name, c.key = f->key, c.tolerance = t.tolerance;
      c.magnitude = std::abs(f->values[0]);
      const auto it = a.uncertainty_k2.find(f->key);
      c.u_k2 = it != a.uncertainty_k2.end() && it->second.size() == 1 ? it->second[0]
                                                                      : std::numeric_limits<double>::quiet_NaN();
      c.decision = decide(c.magnitude, c.u_k2, c.tolerance);
      const double reach = c.magnitude + (std::isfinite(c.u_k2) ? c.u_k2 : 0.0);
      if (!worst || rank(c.decision) > rank(worst->decision) ||
          (rank(c.decision) == rank(worst->decision) &&
           reach > worst->magnitude + (std::isfinite(worst->u_k2) ? worst->u_k2 : 0.0)))
        worst = c;
    }
    if (worst) r.figures.push_back(*worst);
  }
  bool all = !r.figures.empty(), any_non = false;
  for (const auto& f : r.figures)
    all &= f.decision == Conformance::conforming, any_non |= f.decision == Conformance::nonconforming;
  r.overall = any_non ? Conformance::nonconforming : all ? Conformance::conforming : Conformance::undecided;
  return r;
}

}  // namespace eical::dsp
