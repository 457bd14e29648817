#include "dsp/eval/circle_arc.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

CircleResult evaluate_arc(const CircleInput& in, double arc_deg) {
  if (in.pos_mm.size() != in.sample_index.size()) throw InputError("arc evaluation: positions and sample indices differ in length");
  if (!(in.radius_mm > 0.0)) throw InputError("arc evaluation: nominal radius must be positive");
  if (!(arc_deg > 0.0 && arc_deg <= 360.0)) throw InputError("arc evaluation: arc_deg must be in (0, 360]");
  if (in.segments.empty()) throw InputError("arc evaluation: no evaluated arc between two M102 marks");
  CircleResult r;
  r.direction = in.direction;
  r.arc_deg = arc_deg;
  double sum_dev = 0.0, dmax = -INFINITY, dmin = INFINITY;
  std::size_t n_dev = 0;
  for (std::size_t k = 0; k < in.segments.size(); ++k) {
    std::size_t n_here = 0;
    double sum_here = 0.0;
    for (std::size_t i = 0; i < in.sample_index.size(); ++i) {
      if (in.sample_index[i] < in.segments[k].first || in.sample_index[i] >= in.segments[k].second) continue;
      if (!in.pos_mm[i].allFinite()) throw InputError("arc evaluation: non-finite position at sample " + std::to_string(in.sample_index[i]));
      const Eigen::Vector2d d = in.pos_mm[i] - in.center_mm;
      const double dev_um = (d.norm() - in.radius_mm) * 1000.0;
      double ang = std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi;
      if (ang < 0) ang += 360.0;
      r.trace.angle_deg.push_back(ang);
      r.trace.radius_deviation_um.push_back(dev_um);
      r.trace.direction.push_back(in.direction);
      r.trace.revolution.push_back(static_cast<int>(k));
      sum_dev += dev_um, ++n_dev, ++n_here, sum_here += dev_um;
      dmax = std::max(dmax, dev_um), dmin = std::min(dmin, dev_um);
    }
    if (n_here < 20) throw InputError("arc evaluation: arc " + std::to_string(k + 1) + " has only " + std::to_string(n_here) + " samples");
    r.centers_mm.push_back(in.center_mm);
    r.radii_mm.push_back(in.radius_mm + sum_here / static_cast<double>(n_here) / 1000.0);  // mean radius of the arc
  }
  r.revolutions = static_cast<int>(in.segments.size());
  r.radius_mean_deviation_um = sum_dev / static_cast<double>(n_dev);
  r.radial_deviation_F_max_um = dmax;
  r.radial_deviation_F_min_um = dmin;
  r.circular_deviation_G_um = dmax - dmin;
  return r;
}

}  // namespace eical::dsp::eval
