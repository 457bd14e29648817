// Rectangle and free-form programs of a run: both compare the measured path with the
// set-point; the rectangle in its plane at the corner stops, the free form along the
// whole path in 3-D.
#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/program_evaluations.hpp"
#include "dsp/core/error.hpp"

namespace eical::dsp::detail {

void evaluate_rectangle_program(const Run& run, Analysis& a, const EvaluationOptions&) {
  const Measurement& m = a.measurement;
  const auto [ia, ib] = plane_axes(run.meta.program.plane);
  std::vector<Eigen::Vector2d> cmd, meas;
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    cmd.emplace_back(m.cmd_mm[i][ia], m.cmd_mm[i][ib]);
    meas.emplace_back(m.pos_mm[i][ia], m.pos_mm[i][ib]);
  }
  try {
    a.rectangle = eval::evaluate_rectangle(cmd, meas, m.fs_hz);
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "rectangle", std::string("null, ") + e.what()});
    a.degraded = true;
  }
  // With the other axis held along each side (NBS: its velocity is a support of the fusion),
  // its motion across a side is what the support assumes, not what the sensors measured. On
  // nine drawn machines the sides' directions were within their U (the support's, a few
  // µrad) for 33 % of the sides and the corner angles for 65 %; on an independent run with a
  // 3.6 µm bow the straightness came out 9.2 ± 0.05 µm. Without the support U is about
  // 380 µrad and 0.4–3 µm on 40–100 mm sides (the integration noise) and covered.
  if (a.rectangle && a.nbs)
    for (const char* key : kRectangleAcrossSideKeys)
      a.not_evaluated[key] =
          "the other axis is held along each side (NBS), so its motion across a side is assumed, not measured; "
          "analyze --nbs off measures the sides' straightness and direction, to the integration noise (about a "
          "micrometre and a few hundred µrad)";
  // The contour between the corners as well: the rectangle is a free form too.
  try {
    a.path = eval::path_deviation(m.cmd_mm, m.pos_mm, m.fs_hz);
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::path_deviation, "rectangle", e.what()});
  }
}

void evaluate_freeform_program(const Run& run, Analysis& a, const EvaluationOptions&) {
  (void)run;
  const Measurement& m = a.measurement;
  try {
    a.path = eval::path_deviation(m.cmd_mm, m.pos_mm, m.fs_hz);
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "freeform", std::string("null, ") + e.what()});
    a.degraded = true;
  }
}

}  // namespace eical::dsp::detail
