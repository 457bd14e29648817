#include "sim/nc/envelope_check.hpp"

#include "sim/nc/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::sim::nc {
namespace {

// How far the set-point goes and how fast and hard it moves.
struct Reach {
  Eigen::Vector3d min_mm, max_mm;
  double speed_mm_s = 0.0, accel_mm_s2 = 0.0;
  explicit Reach(const Eigen::Vector3d& p) : min_mm(p), max_mm(p) {}
  void add(const Eigen::Vector3d& p) {
    min_mm = min_mm.cwiseMin(p);
    max_mm = max_mm.cwiseMax(p);
  }
};

// An element's extreme points: its ends, and on an arc the plane angles of multiples of
// 90° it sweeps (where one of its plane coordinates is extreme).
void add_element(const PathElement& e, Reach& r) {
  r.add(e.from_mm), r.add(e.to_mm);
  if (!e.is_arc || !(e.length_mm > 0.0)) return;
  const double lo = std::min(e.start_rad, e.start_rad + e.sweep_rad),
               hi = std::max(e.start_rad, e.start_rad + e.sweep_rad);
  const double quarter = 0.5 * std::numbers::pi;
  // At most one turn's four quarters: a longer sweep reaches the same points again.
  const double first = std::ceil(lo / quarter) * quarter;
  for (int k = 0; k < 4 && first + k * quarter <= hi; ++k) {
    const double th = first + k * quarter;
    r.add(e.position((th - e.start_rad) / e.sweep_rad * e.length_mm));
  }
}

Reach trajectory_reach(const Trajectory& tr) {
  Reach r(tr.at(0.0).pos_mm);
  for (const Move& m : tr.moves()) {
    const double v = m.profile.peak_speed();
    r.speed_mm_s = std::max(r.speed_mm_s, v);
    r.accel_mm_s2 = std::max(r.accel_mm_s2, m.profile.peak_accel());
    for (const PathElement& e : m.elements) {
      add_element(e, r);
      if (e.is_arc && e.radius_mm > 0.0) r.accel_mm_s2 = std::max(r.accel_mm_s2, v * v / e.radius_mm);  // v²/R
    }
  }
  return r;
}

Reach sampled_reach(const SetPoint& sp) {
  constexpr double kStepS = 1e-3;
  constexpr double kMaxPoints = 1e7;
  const double duration = std::max(0.0, sp.duration_s());
  const double n = std::min(kMaxPoints, std::ceil(duration / kStepS));
  Reach r(sp.at(0.0).pos_mm);
  for (double i = 0.0; i <= n; i += 1.0) {
    const MotionState s = sp.at(n > 0.0 ? duration * i / n : 0.0);
    r.add(s.pos_mm);
    r.speed_mm_s = std::max(r.speed_mm_s, s.vel_mm_s.norm());
    r.accel_mm_s2 = std::max(r.accel_mm_s2, s.acc_mm_s2.norm());
  }
  return r;
}

// To the micrometre, trailing zeros dropped: a circle's G-code rounds its start point to
// 0.1 µm, so R400 reaches y = 399.99998867, which reads better as 400.
std::string g(double v) {
  char b[512];  // %.3f of the largest double: 309 digits
  std::snprintf(b, sizeof b, "%.3f", v);
  std::string s = b;
  if (s.find('.') != std::string::npos) {
    s.erase(s.find_last_not_of('0') + 1);
    if (s.back() == '.') s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

}  // namespace

std::optional<EnvelopeExcess> envelope_excess(const SetPoint& set_point, const dsp::WorkEnvelope& envelope) {
  const auto* tr = dynamic_cast<const Trajectory*>(&set_point);
  const Reach r = tr ? trajectory_reach(*tr) : sampled_reach(set_point);
  for (int i = 0; i < 3; ++i) {
    // Beyond by more than a micrometre: a program at the travel's end is within it.
    constexpr double kTolMm = 1e-3;
    if (r.max_mm[i] > envelope.travel_mm[i][1] + kTolMm) return EnvelopeExcess{EnvelopeLimit::travel, i, r.max_mm[i]};
    if (r.min_mm[i] < envelope.travel_mm[i][0] - kTolMm) return EnvelopeExcess{EnvelopeLimit::travel, i, r.min_mm[i]};
  }
  const double feed_mm_min = r.speed_mm_s * 60.0;
  if (feed_mm_min > envelope.max_feed_mm_min * (1.0 + 1e-9)) return EnvelopeExcess{EnvelopeLimit::feed, 0, feed_mm_min};
  if (r.accel_mm_s2 > envelope.max_accel_mm_s2 * (1.0 + 1e-9))
    return EnvelopeExcess{EnvelopeLimit::accel, 0, r.accel_mm_s2};
  return std::nullopt;
}

std::string describe(const EnvelopeExcess& excess, const dsp::WorkEnvelope& envelope) {
  switch (excess.limit) {
    case EnvelopeLimit::travel: {
      const std::string axis(1, static_cast<char>('x' + excess.axis));
      return "the program reaches " + axis + " = " + g(excess.value) + " mm, beyond the " + axis + " travel " +
             g(envelope.travel_mm[excess.axis][0]) + ".." + g(envelope.travel_mm[excess.axis][1]) + " mm";
    }
    case EnvelopeLimit::feed:
      return "the program moves at " + g(excess.value) + " mm/min, beyond the maximum feed " +
             g(envelope.max_feed_mm_min) + " mm/min";
    case EnvelopeLimit::accel:
      return "the program accelerates at " + g(excess.value) + " mm/s^2, beyond the maximum acceleration " +
             g(envelope.max_accel_mm_s2) + " mm/s^2";
  }
  return "";
}

const char* envelope_key(const EnvelopeExcess& excess) {
  static constexpr const char* kTravel[3] = {"travel_x_mm", "travel_y_mm", "travel_z_mm"};
  switch (excess.limit) {
    case EnvelopeLimit::travel: return kTravel[excess.axis];
    case EnvelopeLimit::feed: return "max_feed_mm_min";
    case EnvelopeLimit::accel: return "max_accel_mm_s2";
  }
  return "";
}

}  // namespace eical::sim::nc
