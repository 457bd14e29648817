#include "sim/nc/scurve.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace eical::sim::nc {
namespace {

// Acceleration phase from rest to speed v with jerk j and acceleration limit a.
struct Ramp {
  double t_j, t_a, a_peak, t, s;
};

Ramp ramp(double v, double a, double j) {
  Ramp r{};
  if (v * j <= a * a) {  // triangular acceleration: a_max never reached
    r.a_peak = std::sqrt(v * j);
    r.t_j = r.a_peak / j;
    r.t_a = 0.0;
  } else {
    r.a_peak = a;
    r.t_j = a / j;
    r.t_a = v / a - r.t_j;
  }
  r.t = 2.0 * r.t_j + r.t_a;
  r.s = v * r.t / 2.0;  // symmetric acceleration profile: mean speed v/2
  return r;
}

}  // namespace

SCurve::SCurve(double length_mm, double v_max, double a_max, double j_max) : length_(length_mm), j_(j_max) {
  if (!(length_mm >= 0.0) || !(v_max > 0.0) || !(a_max > 0.0) || !(j_max > 0.0))
    throw dsp::InputError("feed profile: length must be >= 0 and the limits positive");
  if (length_mm == 0.0) return;
  double v = v_max;
  Ramp r = ramp(v, a_max, j_max);
  if (2.0 * r.s > length_mm) {
    // Too short to cruise: the largest peak speed whose two ramps fit the length.
    double lo = 0.0, hi = v_max;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (2.0 * ramp(mid, a_max, j_max).s > length_mm ? hi : lo) = mid;
    }
    v = lo;
    r = ramp(v, a_max, j_max);
  }
  v_peak_ = v;
  a_peak_ = r.a_peak;
  t_j_ = r.t_j;
  t_a_ = r.t_a;
  t_acc_ = r.t;
  s_acc_ = r.s;
  t_cruise_ = (length_mm - 2.0 * r.s) / v;
  duration_ = 2.0 * t_acc_ + t_cruise_;
}

PathState SCurve::accel_phase(double t) const {
  const double j = j_, tj = t_j_, ta = t_a_, ap = a_peak_;
  if (t <= tj) return {j * t * t * t / 6.0, j * t * t / 2.0, j * t, j};
  const double s1 = j * tj * tj * tj / 6.0, v1 = j * tj * tj / 2.0;
  if (t <= tj + ta) {
    const double u = t - tj;
    return {s1 + v1 * u + ap * u * u / 2.0, v1 + ap * u, ap, 0.0};
  }
  const double s2 = s1 + v1 * ta + ap * ta * ta / 2.0, v2 = v1 + ap * ta;
  const double u = t - tj - ta;
  return {s2 + v2 * u + ap * u * u / 2.0 - j * u * u * u / 6.0, v2 + ap * u - j * u * u / 2.0, ap - j * u, -j};
}

PathState SCurve::at(double t_s) const {
  if (length_ == 0.0 || t_s <= 0.0) return {};
  if (t_s >= duration_) return {length_, 0.0, 0.0, 0.0};
  if (t_s <= t_acc_) return accel_phase(t_s);
  if (t_s <= t_acc_ + t_cruise_) return {s_acc_ + v_peak_ * (t_s - t_acc_), v_peak_, 0.0, 0.0};
  // Deceleration mirrors the acceleration in time.
  const PathState m = accel_phase(duration_ - t_s);
  return {length_ - m.s, m.v, -m.a, m.j};
}

double SCurve::time_at(double s_mm) const {
  if (s_mm <= 0.0) return 0.0;
  if (s_mm >= length_) return duration_;
  double lo = 0.0, hi = duration_;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi);
    (at(mid).s < s_mm ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace eical::sim::nc
