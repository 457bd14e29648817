#include "tools/comp/proposal.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::tools::comp {

double grid_spacing_mm(const dsp::comp::AxisTable& t, const GridOptions& o) {
  if (o.spacing_mm > 0.0) return o.spacing_mm;
  if (t.pos_mm.size() < 2) throw dsp::InputError("comp: a table needs at least 2 points");
  return (t.last_mm() - t.first_mm()) / static_cast<double>(t.pos_mm.size() - 1);
}

dsp::comp::AxisTable equidistant(const dsp::comp::AxisTable& t, const GridOptions& o) {
  const double spacing = grid_spacing_mm(t, o), range = t.last_mm() - t.first_mm();
  const int n = std::max(2, static_cast<int>(std::ceil(range / spacing - 1e-9)) + 1);
  return dsp::comp::resample(t, t.first_mm(), range / (n - 1), n);
}

}  // namespace eical::tools::comp
