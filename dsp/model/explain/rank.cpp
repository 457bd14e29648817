// Stage: the effects in the order a reader needs them.
#include "dsp/model/explain/stages.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

void rank(ExplainState& st) {
  std::vector<ExplainedEffect>& all = st.effects;
  // Significant first — the table's effects before what lies outside it (other.*: a
  // residual no effect explains at a plausible size is named once the named ones are) —
  // the one that explains most first.
  std::stable_sort(all.begin(), all.end(), [](const ExplainedEffect& a, const ExplainedEffect& b) {
    if (a.significant != b.significant) return a.significant;
    const bool ao = a.name.rfind("other.", 0) == 0, bo = b.name.rfind("other.", 0) == 0;
    if (a.significant && ao != bo) return bo;
    if (a.significant) return a.importance_um > b.importance_um;
    return a.bic_drop > b.bic_drop;
  });
}

}  // namespace eical::dsp::model::stage
