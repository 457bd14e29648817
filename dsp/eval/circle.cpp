#include "dsp/eval/circle.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/index_span.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

CircleFit fit_circle(const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < 3) throw InputError("circle fit: fewer than 3 points");
  // Kasa: x² + y² = 2ax + 2by + c, linear in (a, b, c); centred for conditioning.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  // Its normal equations (3 x 3, no N x 3 matrix: a revolution of a long run holds half a
  // million points): centred, their condition is about (2R)^2 / 1, far from double's limit,
  // and the start only has to lie in Gauss-Newton's basin.
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Aty = Eigen::Vector3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector2d q = p - mean;
    const Eigen::Vector3d row(2 * q.x(), 2 * q.y(), 1.0);
    AtA.noalias() += row * row.transpose();
    Aty.noalias() += row * q.squaredNorm();
  }
  const Eigen::Vector3d k = AtA.ldlt().solve(Aty);
  Eigen::Vector2d c(k[0], k[1]);
  double r = std::sqrt(k[2] + c.squaredNorm());
  // Gauss–Newton on the geometric distances |p − c| − r. The Jacobian's row is (−u, −1)
  // with u the unit vector from the centre, so JᵀJ and Jᵀr are sums of u's products: six
  // and three of them per point instead of 3 x 3 outer products. It stops when a step moves
  // the centre and radius by less than a picometre (the deviations are given to 10 nm): the
  // draws of an unsupported R150 run (millimetres from round) get there in eight iterations;
  // the 1e-13 mm asked for before lay below the sums' rounding, and most fits ran all ten.
  constexpr double kStepMm = 1e-9;
  for (int it = 0; it < 10; ++it) {
    double sxx = 0.0, sxy = 0.0, syy = 0.0, sx = 0.0, sy = 0.0, ex = 0.0, ey = 0.0, e1 = 0.0, n = 0.0;
    for (const auto& p : points) {
      const double dx = p.x() - mean.x() - c.x(), dy = p.y() - mean.y() - c.y();
      const double dist = std::sqrt(dx * dx + dy * dy);
      if (dist <= 0.0) continue;
      const double ux = dx / dist, uy = dy / dist, e = dist - r;
      sxx += ux * ux, sxy += ux * uy, syy += uy * uy, sx += ux, sy += uy, n += 1.0;
      ex += ux * e, ey += uy * e, e1 += e;
    }
    Eigen::Matrix3d JtJ;
    JtJ << sxx, sxy, sx, sxy, syy, sy, sx, sy, n;
    const Eigen::Vector3d step = JtJ.ldlt().solve(Eigen::Vector3d(ex, ey, e1));  // −(Jᵀr), J = (−u, −1)
    c += step.head<2>();
    r += step[2];
    if (step.norm() < kStepMm) break;
  }
  return {c + mean, r};
}

CircleAccumulator::CircleAccumulator(Options o) : o_(std::move(o)) {
  r_.direction = o_.direction;
  r_.arc_deg = o_.arc_deg;
  r_.trace.stride = std::max<std::size_t>(1, o_.trace_stride);
}

void CircleAccumulator::begin(std::size_t expected_samples) {
  pts_.clear();
  last_dev_.clear();
  if (expected_samples > 0) {
    if (o_.arc_deg >= 360.0) pts_.reserve(expected_samples);
    last_dev_.reserve(expected_samples);
  }
  n_here_ = 0, sum_here_ = 0.0;
  open_ = r_.revolutions;
}

void CircleAccumulator::put(const Eigen::Vector2d& d, double dev_um) {
  double ang = std::atan2(d.y(), d.x()) * 180.0 / std::numbers::pi;
  if (ang < 0) ang += 360.0;
  if (o_.keep_trace && (o_.trace_offset + r_.points) % r_.trace.stride == 0) {
    r_.trace.angle_deg.push_back(ang);
    r_.trace.radius_deviation_um.push_back(dev_um);
    r_.trace.direction.push_back(o_.direction);
    r_.trace.revolution.push_back(open_);
  }
  last_dev_.push_back(dev_um);
  const auto k = static_cast<std::size_t>(std::min(359.0, std::floor(ang)));
  r_.deviation_sum_by_deg[k] += dev_um;
  r_.points_by_deg[k] += 1.0;
  ++r_.points;
  sum_dev_ += dev_um;
  dmax_ = std::max(dmax_, dev_um);
  dmin_ = std::min(dmin_, dev_um);
}

void CircleAccumulator::add(std::int64_t sample_index, const Eigen::Vector2d& pos_mm) {
  const bool arc = o_.arc_deg < 360.0;
  if (!pos_mm.allFinite())
    throw InputError(std::string(arc ? "arc" : "circle") + " evaluation: non-finite position at sample " +
                     std::to_string(sample_index));
  if (!arc) {
    pts_.push_back(pos_mm);
    return;
  }
  const Eigen::Vector2d d = pos_mm - o_.center_mm;
  const double dev_um = (d.norm() - o_.radius_mm) * 1000.0;
  put(d, dev_um);
  ++n_here_, sum_here_ += dev_um;
}

void CircleAccumulator::end() {
  const int k = open_;
  open_ = -1;
  if (o_.arc_deg < 360.0) {
    if (n_here_ < 20)
      throw InputError("arc evaluation: arc " + std::to_string(k + 1) + " has only " + std::to_string(n_here_) +
                       " samples");
    r_.centers_mm.push_back(o_.center_mm);
    r_.radii_mm.push_back(o_.radius_mm + sum_here_ / static_cast<double>(n_here_) / 1000.0);  // mean radius of the arc
    ++r_.revolutions;
    return;
  }
  if (pts_.size() < 100)
    throw InputError("circle evaluation: revolution " + std::to_string(k + 1) + " has only " +
                     std::to_string(pts_.size()) + " samples");
  const CircleFit fit = fit_circle(pts_);
  r_.centers_mm.push_back(fit.center);
  r_.radii_mm.push_back(fit.radius);
  open_ = k;  // put() names the revolution
  for (const auto& p : pts_) {
    const Eigen::Vector2d d = p - fit.center;
    put(d, (d.norm() - o_.radius_mm) * 1000.0);
  }
  open_ = -1;
  ++r_.revolutions;
  std::vector<Eigen::Vector2d>().swap(pts_);  // one revolution in memory at a time
}

CircleResult CircleAccumulator::result() const {
  if (r_.revolutions == 0) throw InputError("circle evaluation: no revolution evaluated");
  CircleResult r = r_;
  r.radius_mean_deviation_um = sum_dev_ / static_cast<double>(r.points);
  r.radial_deviation_F_max_um = dmax_;
  r.radial_deviation_F_min_um = dmin_;
  r.circular_deviation_G_um = dmax_ - dmin_;
  const std::size_t d = r.direction == "cw" ? 1 : 0;
  r.direction_F_max_um[d] = dmax_, r.direction_F_min_um[d] = dmin_;
  if (o_.arc_deg >= 360.0 && r.revolutions >= 2) {
    double hi = -kInf, lo = kInf;
    bool every_degree = true;
    for (std::size_t k = 0; k < 360; ++k) {
      if (!(r.points_by_deg[k] > 0.0)) every_degree = false;
      if (!every_degree) break;
      const double mean = r.deviation_sum_by_deg[k] / r.points_by_deg[k];
      hi = std::max(hi, mean), lo = std::min(lo, mean);
    }
    if (every_degree) r.direction_averaged_G_um[d] = hi - lo;
  }
  return r;
}

CircleResult evaluate_circle(const CircleInput& input) {
  if (input.pos_mm.size() != input.sample_index.size())
    throw InputError("circle evaluation: positions and sample indices differ in length");
  if (!(input.radius_mm > 0.0)) throw InputError("circle evaluation: nominal radius must be positive");
  std::vector<std::pair<std::int64_t, std::int64_t>> ranges = input.segments;
  if (ranges.empty()) {
    std::vector<std::int64_t> marks;
    for (auto m : input.segment_marks)
      if (!input.sample_index.empty() && m >= input.sample_index.front() && m <= input.sample_index.back())
        marks.push_back(m);
    std::sort(marks.begin(), marks.end());
    for (std::size_t k = 0; k + 1 < marks.size(); ++k) ranges.emplace_back(marks[k], marks[k + 1]);
  }
  if (ranges.empty())
    throw InputError(
        "circle evaluation: fewer than two M102 marks inside the measurement (a circle program marks each revolution)");
  require_ascending(input.sample_index, "circle evaluation");
  CircleAccumulator acc({input.center_mm, input.radius_mm, input.direction, 360.0, 1, 0, input.keep_trace});
  for (const auto& range : ranges) {
    const IndexSpan in = index_span(input.sample_index, range.first, range.second);
    acc.begin(in.size());
    for (std::size_t i = in.begin; i < in.end; ++i) acc.add(input.sample_index[i], input.pos_mm[i]);
    acc.end();
  }
  return acc.result();
}

CircleResult combine(const CircleResult& a, const CircleResult& b) {
  CircleResult c = a;
  c.direction = a.direction == b.direction ? a.direction : "both";
  c.revolutions = a.revolutions + b.revolutions;
  const double na = static_cast<double>(a.points), nb = static_cast<double>(b.points);
  c.points = a.points + b.points;
  c.radius_mean_deviation_um = (a.radius_mean_deviation_um * na + b.radius_mean_deviation_um * nb) / (na + nb);
  c.radial_deviation_F_max_um = std::max(a.radial_deviation_F_max_um, b.radial_deviation_F_max_um);
  c.radial_deviation_F_min_um = std::min(a.radial_deviation_F_min_um, b.radial_deviation_F_min_um);
  c.circular_deviation_G_um = c.radial_deviation_F_max_um - c.radial_deviation_F_min_um;
  for (std::size_t d = 0; d < 2; ++d) {
    c.direction_F_max_um[d] = std::max(a.direction_F_max_um[d], b.direction_F_max_um[d]),
    c.direction_F_min_um[d] = std::min(a.direction_F_min_um[d], b.direction_F_min_um[d]);
    c.direction_averaged_G_um[d] =
        std::isfinite(a.direction_averaged_G_um[d]) ? a.direction_averaged_G_um[d] : b.direction_averaged_G_um[d];
  }
  c.centers_mm.insert(c.centers_mm.end(), b.centers_mm.begin(), b.centers_mm.end());
  c.radii_mm.insert(c.radii_mm.end(), b.radii_mm.begin(), b.radii_mm.end());
  auto append = [](auto& dst, const auto& src) { dst.insert(dst.end(), src.begin(), src.end()); };
  append(c.trace.angle_deg, b.trace.angle_deg);
  append(c.trace.radius_deviation_um, b.trace.radius_deviation_um);
  append(c.trace.direction, b.trace.direction);
  append(c.trace.revolution, b.trace.revolution);
  for (std::size_t k = 0; k < 360; ++k)
    c.deviation_sum_by_deg[k] += b.deviation_sum_by_deg[k], c.points_by_deg[k] += b.points_by_deg[k];
  if (a.direction != b.direction) {
    // ISO 230-4 H: the largest difference of the two directions' mean deviation per 1° bin.
    double h = 0.0;
    for (std::size_t k = 0; k < 360; ++k) {
      const double ca = a.points_by_deg[k], cb = b.points_by_deg[k];
      if (ca > 0 && cb > 0) h = std::max(h, std::abs(a.deviation_sum_by_deg[k] / ca - b.deviation_sum_by_deg[k] / cb));
    }
    c.circular_hysteresis_H_um = h;
  }
  return c;
}

}  // namespace eical::dsp::eval
