#pragma once
// Two results of the history compared figure by figure: the difference (after − before)
// with its expanded uncertainty. The two measurements are independent, so the combined
// uncertainty is U = √(U_before² + U_after²) at the same coverage (k = 2, about 95 %), and
// a change is significant when |difference| > U. A figure without an uncertainty on both
// sides is shown but not judged.
#include "history/record/record.hpp"

#include <optional>
#include <string>
#include <vector>

namespace eical::history {

enum class Judgement { significant, within_uncertainty, not_judged, missing };

struct FigureChange {
  std::string name;
  std::optional<double> before, after;  // nullopt: not determined / not in that result
  std::optional<double> u_before, u_after;
  std::optional<double> difference;      // after − before
  std::optional<double> uncertainty_k2;  // of the difference
  Judgement judgement = Judgement::missing;
};

struct Comparison {
  Summary before, after;
  std::vector<FigureChange> figures;        // every figure of either result, by name
  std::vector<std::string> not_comparable;  // e.g. "circle.feed_mm_min: 2500 → 1000 (a different test)"
};

Comparison compare(const Record& before, const Record& after);

const char* judgement_name(Judgement j);  // "significant", "within_uncertainty", "not_judged", "missing"

}  // namespace eical::history
