#include "dsp/analysis/verdict.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/core/key_unit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace eical::dsp {
namespace {

// `v` in the unit `key` names, as a person reads it.
std::string num(double v, const char* key) {
  const std::string unit = unit_of_key(key);
  char b[64];
  const double a = std::abs(v);
  if (unit == "µm" && a >= 1000.0)
    std::snprintf(b, sizeof b, "%.2f mm", v / 1000.0);
  else
    std::snprintf(b, sizeof b, a >= 100.0 ? "%.0f %s" : a >= 10.0 ? "%.1f %s" : "%.2f %s", v, unit.c_str());
  return b;
}

// The figure's ISO 14253-1 decision when the run was judged against tolerances and the
// decision is proven, conformance or non-conformance; null otherwise.
const FigureConformance* proven_either_way(const Analysis& a, const std::string& key) {
  if (!a.conformance) return nullptr;
  for (const auto& f : a.conformance->figures)
    if (f.key == key && f.decision != Conformance::undecided) return &f;
  return nullptr;
}

}  // namespace

const ResolutionLimit* resolution_limit(ProgramKind program) {
  const auto& r = program_descriptor(program).resolution;
  return r ? &*r : nullptr;
}

void judge(const Program& program, Analysis& a) {
  a.verdict_reasons.clear();
  bool not_measurable = false;
  std::string decided_note;  // said under the verdict, not a reason for a lesser one
  const ResolutionLimit* lim = resolution_limit(program.kind);
  const std::vector<FigureValue> figs = figures_of(a);
  auto u_of = [&](const char* key) -> double {
    const auto it = a.uncertainty_k2.find(key);
    return it != a.uncertainty_k2.end() && it->second.size() == 1 ? it->second[0]
                                                                  : std::numeric_limits<double>::quiet_NaN();
  };
  if (lim) {
    const FigureValue* h = find_figure(figs, lim->headline);
    const FigureValue* l = find_figure(figs, lim->limited);
    const Flag* unsupported = find_flag(a.flags, FlagCode::position_unsupported);
    if (!h && unsupported) {
      // Nothing holds the double integral: no position figure at all, whatever its size.
      not_measurable = true;
      a.verdict_reasons.push_back(std::string(lim->name) + " is not measurable: " + unsupported->detail);
    } else if (!h || !l) {
      a.verdict_reasons.push_back(std::string(lim->name) + " could not be determined (see the flags)");
    } else if (a.uncertainty_k2.empty()) {
      a.verdict_reasons.push_back("the figures' uncertainty was not estimated" +
                                  (a.uncertainty_note.empty() ? "" : ": " + a.uncertainty_note));
    } else {
      const double ul = u_of(lim->limited);
      // With tolerances (ISO 14253-1) the tolerance, not the program's fixed limit, says
      // what U must resolve: a figure the decision proves either way was measured well
      // enough for it, whatever its U against the limit.
      const FigureConformance* decided = proven_either_way(a, lim->limited);
      if (decided && !(ul <= lim->limit)) {
        decided_note =
            ("U(" + std::string(lim->limited_name) + ") = " + num(ul, lim->limited) + " exceeds the " +
             num(lim->limit, lim->limited) + " a " + program_kind_name(program.kind) +
             " test resolves without tolerances, but decides its tolerance of " +
             num(decided->tolerance, lim->limited) + ": " + conformance_words(decided->decision) + " (ISO 14253-1)");
      } else if (!std::isfinite(ul) || ul > lim->limit) {
        not_measurable = true;
        a.verdict_reasons.push_back("U(" + std::string(lim->limited_name) +
                                    ") = " + (std::isfinite(ul) ? num(ul, lim->limited) : std::string("unknown")) +
                                    " exceeds the " + num(lim->limit, lim->limited) + " a " +
                                    program_kind_name(program.kind) + " test is meant to resolve");
      }
    }
  }
  if (not_measurable)
    a.verdict = Verdict::not_measurable;
  else if (a.degraded || (lim && !a.verdict_reasons.empty()))
    a.verdict = Verdict::degraded;
  else
    a.verdict = Verdict::ok;
  if (!decided_note.empty()) a.verdict_reasons.push_back(decided_note);
  if (a.degraded)
    for (const Flag& f : a.flags)
      if (severity(f) == FlagSeverity::critical && f.code != FlagCode::position_unsupported)
        a.verdict_reasons.push_back(flag_text(f));
}

}  // namespace eical::dsp
