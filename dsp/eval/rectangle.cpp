#include "dsp/eval/rectangle.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <utility>

namespace eical::dsp::eval {
namespace {

// Total-least-squares line through points: centroid and unit direction.
std::pair<Eigen::Vector2d, Eigen::Vector2d> fit_line(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) cov += (p - c) * (p - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  return {c, es.eigenvectors().col(1)};  // largest eigenvalue = direction
}

double signed_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
}

}  // namespace

RectangleResult evaluate_rectangle(const std::vector<Eigen::Vector2d>& cmd_mm,
                                   const std::vector<Eigen::Vector2d>& meas_mm, double fs_hz, double min_stop_s) {
  if (cmd_mm.size() != meas_mm.size()) throw InputError("rectangle: command and measurement differ in length");
  if (!(fs_hz > 0.0)) throw InputError("rectangle: fs_hz must be positive");
  for (std::size_t i = 0; i < cmd_mm.size(); ++i)
    if (!cmd_mm[i].allFinite() || !meas_mm[i].allFinite())
      throw InputError("rectangle: non-finite position at sample " + std::to_string(i));
  const auto min_stop = static_cast<std::size_t>(std::max(1.0, min_stop_s * fs_hz));

  std::vector<std::pair<std::size_t, std::size_t>> stops;
  for (std::size_t i = 0; i < cmd_mm.size();) {
    std::size_t j = i + 1;
    while (j < cmd_mm.size() && (cmd_mm[j] - cmd_mm[i]).norm() <= 1e-9) ++j;
    if (j - i >= min_stop) stops.emplace_back(i, j);
    i = j;
  }
  if (stops.size() < 3)
    throw InputError("rectangle: fewer than 3 stops of the set-point (is the program run with G61?)");

  RectangleResult r;
  for (const auto& [b, e] : stops) {
    Eigen::Vector2d err = Eigen::Vector2d::Zero();
    for (std::size_t k = b; k < e; ++k) err += meas_mm[k] - cmd_mm[k];
    r.corners_mm.push_back(cmd_mm[b]);
    r.corner_errors_um.push_back(err / static_cast<double>(e - b) * 1000.0);
  }
  std::vector<Eigen::Vector2d> measured_dirs;
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    RectangleSide side;
    side.from_mm = cmd_mm[stops[k].first];
    side.to_mm = cmd_mm[stops[k + 1].first];
    const Eigen::Vector2d cmd_dir = (side.to_mm - side.from_mm).normalized();
    // The side proper: the samples between the stops, without the acceleration phases'
    // first and last 10 % of the path (where servo transients dominate).
    std::vector<Eigen::Vector2d> pts;
    const double len = (side.to_mm - side.from_mm).norm();
    for (std::size_t i = stops[k].second; i < stops[k + 1].first; ++i) {
      const double u = (cmd_mm[i] - side.from_mm).dot(cmd_dir) / len;
      if (u > 0.1 && u < 0.9) pts.push_back(meas_mm[i]);
    }
    if (pts.size() < 3) throw InputError("rectangle: side " + std::to_string(k + 1) + " has too few samples");
    auto [c, dir] = fit_line(pts);
    if (dir.dot(cmd_dir) < 0) dir = -dir;
    const Eigen::Vector2d normal(-dir.y(), dir.x());
    double lo = kInf, hi = -kInf;
    for (const auto& p : pts) {
      const double d = (p - c).dot(normal);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    side.straightness_um = (hi - lo) * 1000.0;
    side.direction_error_urad = signed_angle(cmd_dir, dir) * 1e6;
    measured_dirs.push_back(dir);
    r.sides.push_back(side);
  }
  for (std::size_t k = 0; k + 1 < r.sides.size(); ++k) {
    const Eigen::Vector2d c0 = (r.sides[k].to_mm - r.sides[k].from_mm).normalized();
    const Eigen::Vector2d c1 = (r.sides[k + 1].to_mm - r.sides[k + 1].from_mm).normalized();
    r.corner_angle_error_urad.push_back((signed_angle(measured_dirs[k], measured_dirs[k + 1]) - signed_angle(c0, c1)) *
                                        1e6);
  }
  return r;
}

}  // namespace eical::dsp::eval
