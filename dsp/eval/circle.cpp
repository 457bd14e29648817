#include "dsp/eval/circle.hpp"

#include "dsp/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

CircleFit fit_circle(const std::vector<Eigen::Vector2d>& pts) {
  if (pts.size() < 3) throw InputError("circle fit: fewer than 3 points");
  // Kasa: x² + y² = 2ax + 2by + c, linear in (a, b, c); centred for conditioning.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d q = pts[i] - mean;
    A.row(static_cast<Eigen::Index>(i)) << 2 * q.x(), 2 * q.y(), 1.0;
    y(static_cast<Eigen::Index>(i)) = q.squaredNorm();
  }
  const Eigen::Vector3d k = A.colPivHouseholderQr().solve(y);
  Eigen::Vector2d c(k[0], k[1]);
  double r = std::sqrt(k[2] + c.squaredNorm());
  // Gauss–Newton on the geometric distances |p − c| − r.
  for (int it = 0; it < 10; ++it) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (const auto& p : pts) {
      const Eigen::Vector2d d = p - mean - c;
      const double dist = d.norm();
      if (dist <= 0.0) continue;
      const Eigen::Vector3d j(-d.x() / dist, -d.y() / dist, -1.0);
      JtJ += j * j.transpose();
      Jtr += j * (dist - r);
    }
    const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
    c += step.head<2>();
    r += step[2];
    if (step.norm() < 1e-13) break;
  }
  return {c + mean, r};
}

CircleResult evaluate_circle(const CircleInput& in) {
  if (in.pos_mm.size() != in.sample_index.size()) throw InputError("circle evaluation: positions and sample indices differ in length");
  if (!(in.radius_mm > 0.0)) throw InputError("circle evaluation: nominal radius must be positive");
  std::vector<std::pair<std::int64_t, std::int64_t>> ranges = in.segments;
  if (ranges.empty()) {
    std::vector<std::int64_t> marks;
    for (auto m : in.segment_marks)
      if (!in.sample_index.empty() && m >= in.sample_index.front() && m <= in.sample_index.back()) marks.push_back(m);
    std::sort(marks.begin(), marks.end());
    for (std::size_t k = 0; k + 1 < marks.size(); ++k) ranges.emplace_back(marks[k], marks[k + 1]);
  }
  if (ranges.empty())
    throw InputError("circle evaluation: fewer than two M102 marks inside the measurement (a circle program marks each revolution)");

  CircleResult r;
  r.direction = in.direction;
  double sum_dev = 0.0;
  std::size_t n_dev = 0;
  double dmax = -INFINITY, dmin = INFINITY;
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    std::vector<Eigen::Vector2d> pts;
    for (std::size_t i = 0; i < in.sample_index.size(); ++i)
      if (in.sample_index[i] >= ranges[k].first && in.sample_index[i] < ranges[k].second) {
        if (!in.pos_mm[i].allFinite()) throw InputError("circle evaluation: non-finite position at sample " + std::to_string(in.sample_index[i]));
        pts.push_back(in.pos_mm[i]);
      }
    if (pts.size() < 100) throw InputError("circle evaluation: revolution " + std::to_string(k + 1) + " has only " + std::to_string(pts.size()) + " samples");
    const CircleFit fit = fit_circle(pts);
    r.centers_mm.push_back(fit.center);
    r.radii_mm.push_back(fit.radius);
    for (const auto& p : pts) {
      const Eigen::Vector2d d = p - fit.center;
      const double dev_um = (d.norm() - in.radius_mm) * 1000.0;
      double ang = std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi;
      if (ang < 0) ang += 360.0;
      r.trace.angle_deg.push_back(ang);
      r.trace.radius_deviation_um.push_back(dev_um);
      r.trace.direction.push_back(in.direction);
      r.trace.revolution.push_back(static_cast<int>(k));
      sum_dev += dev_um;
      ++n_dev;
      dmax = std::max(dmax, dev_um);
      dmin = std::min(dmin, dev_um);
    }
  }
  r.revolutions = static_cast<int>(ranges.size());
  r.radius_mean_deviation_um = sum_dev / static_cast<double>(n_dev);
  r.radial_deviation_F_max_um = dmax;
  r.radial_deviation_F_min_um = dmin;
  r.circular_deviation_G_um = dmax - dmin;
  return r;
}

CircleResult combine(const CircleResult& a, const CircleResult& b) {
  CircleResult c = a;
  c.direction = a.direction == b.direction ? a.direction : "both";
  c.revolutions = a.revolutions + b.revolutions;
  const double na = static_cast<double>(a.trace.radius_deviation_um.size()), nb = static_cast<double>(b.trace.radius_deviation_um.size());
  c.radius_mean_deviation_um = (a.radius_mean_deviation_um * na + b.radius_mean_deviation_um * nb) / (na + nb);
  c.radial_deviation_F_max_um = std::max(a.radial_deviation_F_max_um, b.radial_deviation_F_max_um);
  c.radial_deviation_F_min_um = std::min(a.radial_deviation_F_min_um, b.radial_deviation_F_min_um);
  c.circular_deviation_G_um = c.radial_deviation_F_max_um - c.radial_deviation_F_min_um;
  c.centers_mm.insert(c.centers_mm.end(), b.centers_mm.begin(), b.centers_mm.end());
  c.radii_mm.insert(c.radii_mm.end(), b.radii_mm.begin(), b.radii_mm.end());
  auto append = [](auto& dst, const auto& src) { dst.insert(dst.end(), src.begin(), src.end()); };
  append(c.trace.angle_deg, b.trace.angle_deg);
  append(c.trace.radius_deviation_um, b.trace.radius_deviation_um);
  append(c.trace.direction, b.trace.direction);
  append(c.trace.revolution, b.trace.revolution);
  if (a.direction != b.direction) {
    std::vector<double> sa(360, 0.0), sb(360, 0.0), ca(360, 0.0), cb(360, 0.0);
    auto bin = [](const CircleResult& r, std::vector<double>& s, std::vector<double>& n) {
      for (std::size_t i = 0; i < r.trace.angle_deg.size(); ++i) {
        const auto k = static_cast<std::size_t>(std::min(359.0, std::floor(r.trace.angle_deg[i])));
        s[k] += r.trace.radius_deviation_um[i];
        n[k] += 1.0;
      }
    };
    bin(a, sa, ca);
    bin(b, sb, cb);
    double h = 0.0;
    for (std::size_t k = 0; k < 360; ++k)
      if (ca[k] > 0 && cb[k] > 0) h = std::max(h, std::abs(sa[k] / ca[k] - sb[k] / cb[k]));
    c.circular_hysteresis_H_um = h;
  }
  return c;
}

}  // namespace eical::dsp::eval
