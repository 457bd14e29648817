#include "dsp/analysis/figures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace eical::dsp {
namespace {

struct Out {
  std::vector<FigureValue>& f;
  void scalar(const std::string& key, double v) {
    if (std::isfinite(v)) f.push_back({key, {v}, false, 1});
  }
  void array(const std::string& key, std::vector<double> v, int columns = 1) {
    f.push_back({key, std::move(v), true, columns});
  }
};

void circle_figures(const Analysis& a, Out& o) {
  const auto& c = *a.circle;
  o.scalar("circle.radius_mean_deviation_um", c.radius_mean_deviation_um);
  o.scalar("circle.circular_deviation_G_um", c.circular_deviation_G_um);
  if (c.circular_hysteresis_H_um) o.scalar("circle.circular_hysteresis_H_um", *c.circular_hysteresis_H_um);
  o.scalar("circle.radial_deviation_F_max_um", c.radial_deviation_F_max_um);
  o.scalar("circle.radial_deviation_F_min_um", c.radial_deviation_F_min_um);
  o.scalar("circle.averaged_revolution_G_ccw_um", c.direction_averaged_G_um[0]);
  o.scalar("circle.averaged_revolution_G_cw_um", c.direction_averaged_G_um[1]);
  if (c.direction == "both") {
    o.scalar("circle.circular_deviation_G_ccw_um", direction_G_um(c, "ccw"));
    o.scalar("circle.circular_deviation_G_cw_um", direction_G_um(c, "cw"));
  }
}

void diagnostics_figures(const Analysis& a, Out& o) {
  const auto& d = *a.diagnostics;
  const std::pair<const char*, double> f[] = {{"backlash_x_um", d.backlash_x_um},
                                              {"backlash_y_um", d.backlash_y_um},
                                              {"reversal_spike_x_um", d.reversal_spike_x_um},
                                              {"reversal_spike_y_um", d.reversal_spike_y_um},
                                              {"lateral_play_x_um", d.lateral_play_x_um},
                                              {"lateral_play_y_um", d.lateral_play_y_um},
                                              {"cyclic_error_x_um", d.cyclic_error_x_um},
                                              {"cyclic_error_y_um", d.cyclic_error_y_um},
                                              {"squareness_urad", d.squareness_urad},
                                              {"scale_mismatch_ppm", d.scale_mismatch_ppm},
                                              {"straightness_x_um", d.straightness_x_um},
                                              {"straightness_y_um", d.straightness_y_um},
                                              {"stick_slip_um", d.stick_slip_um},
                                              {"vibration_um", d.vibration_um},
                                              {"servo_lag_x_ms", d.lag_x_ms},
                                              {"servo_lag_y_ms", d.lag_y_ms},
                                              {"model_residual_rms_um", d.residual_rms_um}};
  for (const auto& [k, v] : f) o.scalar(std::string("diagnostics.") + k, v);
  if (d.servo_and_squareness_separated) o.scalar("diagnostics.servo_mismatch_ms", d.servo_mismatch_ms);
}

void positioning_figures(const Analysis& a, Out& o) {
  const auto& r = *a.positioning;
  for (const auto& [k, v] : eval::iso230_2_figures(r)) o.scalar(std::string("positioning.") + k, v);
  for (const auto& [k, v] : eval::vdi3441_figures(r.vdi)) o.scalar(std::string("positioning.vdi3441.") + k, v);
  std::vector<double> mu, md, m, b, rr;
  for (const auto& t : r.targets)
    mu.push_back(t.mean_up_um), md.push_back(t.mean_down_um), m.push_back(t.mean_um), b.push_back(t.B_um),
        rr.push_back(t.R_um);
  o.array("positioning.per_target.mean_up_um", mu);
  o.array("positioning.per_target.mean_down_um", md);
  o.array("positioning.per_target.mean_um", m);
  o.array("positioning.per_target.B_um", b);
  o.array("positioning.per_target.R_um", rr);
}

void step_figures(const Analysis& a, Out& o) {
  const auto& s = *a.step;
  o.scalar("step.end_position_error_um", s.end_position_error_um);
  o.scalar("step.overshoot_um", s.overshoot_um);
  o.scalar("step.noise_um", s.noise_um);
  if (std::any_of(s.moves.begin(), s.moves.end(), [](const eval::StepMove& m) { return m.settled; }))
    o.scalar("step.settling_s", s.settling_s);
  bool repeat = false;
  for (std::size_t i = 0; i < s.moves.size(); ++i)
    for (std::size_t k = i + 1; k < s.moves.size(); ++k)
      repeat |= std::abs(s.moves[i].to_mm - s.moves[k].to_mm) < 1e-6 &&
                (s.moves[i].to_mm > s.moves[i].from_mm) == (s.moves[k].to_mm > s.moves[k].from_mm);
  if (repeat) o.scalar("step.scatter_um", s.scatter_um);
  std::vector<double> step, end;
  double largest = 0.0;
  for (const auto& m : s.moves) {
    step.push_back(m.step_measured_um), end.push_back(m.end_error_um);
    largest = std::max(largest, std::abs(m.step_measured_um));
  }
  o.scalar("step.largest_step_measured_um", largest);
  o.array("step.moves.step_measured_um", step);
  o.array("step.moves.end_error_um", end);
}

void path_figures(const std::string& prefix, const eval::PathDeviation& p, Out& o) {
  o.scalar(prefix + ".contour_error_max_um", p.contour_error_max_um);
  o.scalar(prefix + ".contour_error_rms_um", p.contour_error_rms_um);
  o.scalar(prefix + ".tangential_rms_um", p.tangential_rms_um);
}

void rectangle_figures(const Analysis& a, Out& o) {
  const auto& r = *a.rectangle;
  std::vector<double> corners, straight, direction;
  double worst = 0.0;
  for (const auto& e : r.corner_errors_um)
    corners.push_back(e.x()), corners.push_back(e.y()), worst = std::max(worst, e.norm());
  o.scalar("rectangle.corner_error_max_um", worst);
  o.array("rectangle.corner_errors_um", corners, 2);
  for (const auto& s : r.sides) straight.push_back(s.straightness_um), direction.push_back(s.direction_error_urad);
  o.array(kRectangleStraightnessKey, straight);
  o.array(kRectangleDirectionKey, direction);
  o.array(kRectangleCornerAngleKey, r.corner_angle_error_urad);
}

}  // namespace

double direction_G_um(const eval::CircleResult& circle, const std::string& direction) {
  // From every point of the direction (the trace of a long run keeps every n-th only).
  if (direction != "ccw" && direction != "cw") return std::numeric_limits<double>::quiet_NaN();
  const std::size_t d = direction == "cw" ? 1 : 0;
  const double hi = circle.direction_F_max_um[d], lo = circle.direction_F_min_um[d];
  return hi >= lo ? hi - lo : std::numeric_limits<double>::quiet_NaN();
}

std::vector<FigureValue> figures_of(const Analysis& analysis) {
  std::vector<FigureValue> f;
  Out o{f};
  if (analysis.circle) circle_figures(analysis, o);
  if (analysis.diagnostics) diagnostics_figures(analysis, o);
  if (analysis.positioning) positioning_figures(analysis, o);
  if (analysis.step) step_figures(analysis, o);
  if (analysis.rectangle) rectangle_figures(analysis, o);
  if (analysis.path)
    path_figures(
        analysis.rectangle || analysis.program_kind == ProgramKind::rectangle ? "rectangle.path_deviation" : "freeform",
        *analysis.path, o);
  return f;
}

const FigureValue* find_figure(const std::vector<FigureValue>& figures, const std::string& key) {
  for (const auto& f : figures)
    if (f.key == key) return &f;
  return nullptr;
}

}  // namespace eical::dsp
