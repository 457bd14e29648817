#include "dsp/eval/path_deviation.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace eical::dsp::eval {

PathDeviation path_deviation(const std::vector<Eigen::Vector3d>& cmd_mm, const std::vector<Eigen::Vector3d>& meas_mm,
                             double fs_hz, const PathDeviationOptions& options) {
  if (cmd_mm.size() != meas_mm.size()) throw InputError("path deviation: command and measurement differ in length");
  if (cmd_mm.size() < 3) throw InputError("path deviation: fewer than 3 samples");
  if (!(fs_hz > 0.0)) throw InputError("path deviation: fs_hz must be positive");
  for (std::size_t i = 0; i < cmd_mm.size(); ++i)
    if (!cmd_mm[i].allFinite() || !meas_mm[i].allFinite())
      throw InputError("path deviation: non-finite position at sample " + std::to_string(i));

  const std::size_t n = cmd_mm.size();
  std::vector<double> s(n, 0.0);  // arc length of the commanded path at each sample
  for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + (cmd_mm[i] - cmd_mm[i - 1]).norm();
  if (s.back() <= 0.0) throw InputError("path deviation: the commanded path never moves");

  const auto window = static_cast<std::size_t>(std::max(1.0, options.search_window_s * fs_hz));
  const double min_step_mm = options.min_speed_mm_s / fs_hz;
  PathDeviation out;
  double ss_n = 0.0, ss_t = 0.0;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector3d local_dir = cmd_mm[i + 1] - cmd_mm[i - 1];
    if (local_dir.norm() < 2.0 * min_step_mm) continue;  // at rest or reversing
    // Closest point on the polyline segments within the window.
    const std::size_t lo = i > window ? i - window : 0;
    const std::size_t hi = std::min(n - 1, i + window);
    double best_d2 = kInf, best_s = 0.0;
    Eigen::Vector3d best_p = cmd_mm[i], best_t = local_dir.normalized();
    for (std::size_t k = lo; k < hi; ++k) {
      const Eigen::Vector3d seg = cmd_mm[k + 1] - cmd_mm[k];
      const double len2 = seg.squaredNorm();
      if (len2 <= 0.0) continue;
      const double u = std::clamp((meas_mm[i] - cmd_mm[k]).dot(seg) / len2, 0.0, 1.0);
      const Eigen::Vector3d p = cmd_mm[k] + u * seg;
      const double d2 = (meas_mm[i] - p).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best_p = p, best_s = s[k] + u * std::sqrt(len2), best_t = seg / std::sqrt(len2);
    }
    const Eigen::Vector3d dev = meas_mm[i] - best_p;
    const Eigen::Vector3d normal = dev - dev.dot(best_t) * best_t;
    // In-plane sign: left of travel is positive when the path lies in a plane with a
    // dominant normal; use the z-component of t × dev for xy paths, else the magnitude.
    const double side = best_t.cross(dev).z();
    const double normal_um = (side >= 0.0 ? 1.0 : -1.0) * normal.norm() * 1000.0;
    // Tangential: how far the measured point is ahead of the same-sample set-point.
    const double tangential_um = (best_s - s[i]) * 1000.0;
    out.arc_length_mm.push_back(best_s);
    out.normal_um.push_back(normal_um);
    out.normal_magnitude_um.push_back(normal.norm() * 1000.0);
    out.tangential_um.push_back(tangential_um);
    out.sample.push_back(i);
    out.contour_error_max_um = std::max(out.contour_error_max_um, normal.norm() * 1000.0);
    ss_n += normal.squaredNorm() * 1e6;
    ss_t += tangential_um * tangential_um;
  }
  if (out.sample.empty()) throw InputError("path deviation: no sample moves faster than min_speed_mm_s");
  const auto m = static_cast<double>(out.sample.size());
  out.contour_error_rms_um = std::sqrt(ss_n / m);
  out.tangential_rms_um = std::sqrt(ss_t / m);
  return out;
}

}  // namespace eical::dsp::eval
