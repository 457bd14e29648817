#include "dsp/analysis/figures_on_path.hpp"

namespace eical::dsp {

std::vector<FigureValue> figures_on_path(const Run& run, const std::vector<Eigen::Vector3d>& path_mm,
                                         const Analysis& measured) {
  Analysis t;
  t.measurement = measured.measurement;
  const std::int64_t first = run.frames.front().sample_index;
  for (std::size_t k = 0; k < t.measurement.pos_mm.size(); ++k) {
    const auto i = static_cast<std::size_t>(t.measurement.sample_index[k] - first);
    if (i < path_mm.size()) t.measurement.pos_mm[k] = path_mm[i];
  }
  EvaluationOptions eo;
  eo.reference = false;
  if (measured.diagnostics) eo.cyclic_pitch_mm = measured.diagnostics->cyclic_pitch_mm;
  evaluate_program(run, t, eo);
  return figures_of(t);
}

}  // namespace eical::dsp
