#include "sim/nc/klipper_excitation.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace eical::sim::nc {
namespace {

// (end time, acceleration) of each entry, as gen_test returns them.
struct Entry {
  double t_end_s, accel_mm_s2;
};

std::vector<Entry> pulse_entries(const KlipperTest& k) {
  std::vector<Entry> out;
  double freq = k.freq_start_hz, t = 0.0, sign = 1.0;
  while (freq <= k.freq_end_hz + 1e-6) {
    const double t_seg = 0.25 / freq, accel = k.accel_per_hz * freq;
    t += t_seg;
    out.push_back({t, sign * accel});
    t += t_seg;
    out.push_back({t, -sign * accel});
    freq += 2.0 * t_seg * k.hz_per_sec;
    sign = -sign;
  }
  return out;
}

// SweepingVibrationsTestGenerator.gen_test: the slow ±sweeping acceleration switched in
// between the pulse entries.
std::vector<Entry> with_sweep(const std::vector<Entry>& pulses, const KlipperTest& k) {
  if (!(k.sweeping_period_s > 0.0) || !(k.sweeping_accel_mm_s2 > 0.0)) return pulses;
  std::vector<Entry> out;
  double fraction = std::sqrt(2.0) * 0.125;
  double t_rem = k.sweeping_period_s * fraction;
  fraction += 0.25;
  double last_t = 0.0, sig = 1.0;
  for (const Entry& e : pulses) {
    double t_seg = e.t_end_s - last_t;
    while (t_rem <= t_seg) {
      last_t += t_rem;
      out.push_back({last_t, e.accel_mm_s2 + k.sweeping_accel_mm_s2 * sig});
      t_seg -= t_rem;
      t_rem = k.sweeping_period_s * fraction;
      fraction = 0.5;
      sig = -sig;
    }
    t_rem -= t_seg;
    out.push_back({e.t_end_s, e.accel_mm_s2 + k.sweeping_accel_mm_s2 * sig});
    last_t = e.t_end_s;
  }
  return out;
}

std::vector<AccelSegment> current_segments(const KlipperTest& k) {
  const std::vector<Entry> entries = with_sweep(pulse_entries(k), k);
  std::vector<AccelSegment> seg;
  double last_t = 0.0, v = 0.0;
  for (const Entry& e : entries) {
    const double dt = e.t_end_s - last_t;
    if (dt > 0.0) seg.push_back({dt, e.accel_mm_s2});
    v += e.accel_mm_s2 * dt;
    last_t = e.t_end_s;
  }
  // run_test: "Decelerate to a stop, continuing in the direction of motion" at max_accel.
  if (std::abs(v) > 1e-6)
    seg.push_back({std::abs(v) / k.stop_accel_mm_s2, v > 0.0 ? -k.stop_accel_mm_s2 : k.stop_accel_mm_s2});
  return seg;
}

// The older executor's moves as the lookahead plans them. v = accel·t_seg = accel_per_hz/4
// is every move's speed limit, and L = ½·accel·t_seg² is exactly the distance over which
// accel brings 0 to v: so each move out from the centre decelerates from v to rest at the
// reversal (±accel for t_seg), and each move back accelerates to v at the centre, where the
// next move continues in the same direction (a collinear junction: no slowdown). The head
// passes the centre at v; only the first move (from rest) and the last (to rest) are
// triangles, ±accel for t_seg/√2 each way.
std::vector<AccelSegment> legacy_segments(const KlipperTest& k) {
  std::vector<AccelSegment> seg;
  double freq = k.freq_start_hz, sign = 1.0;
  bool first = true;
  while (freq <= k.freq_end_hz + 1e-6) {
    const double t_seg = 0.25 / freq, accel = k.accel_per_hz * freq;
    const double half = t_seg / std::sqrt(2.0);  // a triangle over L = ½·a·t_seg²
    const double next_freq = freq + 2.0 * t_seg * k.hz_per_sec;
    const bool last = !(next_freq <= k.freq_end_hz + 1e-6);
    if (first)
      seg.push_back({half, sign * accel}), seg.push_back({half, -sign * accel});
    else
      seg.push_back({t_seg, -sign * accel});  // out: from v at the centre to rest
    if (last)
      seg.push_back({half, -sign * accel}), seg.push_back({half, sign * accel});
    else
      seg.push_back({t_seg, -sign * accel});  // back: from rest to v at the centre
    first = false;
    freq = next_freq;
    sign = -sign;
  }
  return seg;
}

}  // namespace

KlipperTest KlipperTest::current() { return KlipperTest{}; }

KlipperTest KlipperTest::legacy() {
  KlipperTest k;
  k.freq_end_hz = 10000.0 / 75.0;
  k.accel_per_hz = 75.0;
  k.sweeping_accel_mm_s2 = 0.0;
  k.sweeping_period_s = 0.0;
  k.legacy_moves = true;
  return k;
}

std::string KlipperTest::invalid_reason() const {
  if (!(freq_start_hz >= 1.0)) return "freq_start must be at least 1 Hz (Klipper's limit)";
  if (!(freq_end_hz >= freq_start_hz)) return "freq_end must not be below freq_start";
  if (!(freq_end_hz <= 300.0)) return "freq_end must not exceed 300 Hz (Klipper's limit)";
  if (!(accel_per_hz > 0.0)) return "accel_per_hz must be positive";
  if (!(hz_per_sec > 0.0 && hz_per_sec <= 2.0)) return "hz_per_sec must be in (0, 2] (Klipper's limit)";
  if (!(sweeping_accel_mm_s2 >= 0.0) || !(sweeping_period_s >= 0.0))
    return "sweeping_accel and sweeping_period must not be negative";
  if (!(stop_accel_mm_s2 > 0.0)) return "the stop acceleration (max_accel) must be positive";
  // The segments are built before anything is simulated: bound their number.
  if ((freq_end_hz - freq_start_hz) / hz_per_sec > kMaxSweepS)
    return "hz_per_sec: the sweep from freq_start to freq_end would run " +
           std::to_string(std::lround((freq_end_hz - freq_start_hz) / hz_per_sec)) + " s, more than " +
           std::to_string(static_cast<int>(kMaxSweepS)) + " s";
  if (sweeping_period_s > 0.0 && sweeping_period_s < 0.1) return "sweeping_period must be 0 or at least 0.1 s";
  if (legacy_moves && sweeping_accel_mm_s2 > 0.0 && sweeping_period_s > 0.0)
    return "the older Klipper test has no sweeping";
  return "";
}

std::vector<AccelSegment> klipper_segments(const KlipperTest& test) {
  const std::string why = test.invalid_reason();
  if (!why.empty()) throw dsp::InputError("Klipper resonance test: " + why);
  return test.legacy_moves ? legacy_segments(test) : current_segments(test);
}

AccelProfileSetPoint::AccelProfileSetPoint(std::vector<AccelSegment> segments, const Eigen::Vector3d& direction,
                                           const Eigen::Vector3d& start_mm, double lead_in_s, double tail_s)
    : segments_(std::move(segments)), start_mm_(start_mm), lead_in_(lead_in_s) {
  if (segments_.empty()) throw dsp::InputError("acceleration profile: no segments");
  if (!(direction.norm() > 0.0) || !direction.allFinite())
    throw dsp::InputError("acceleration profile: the direction must be a non-zero vector");
  if (!(lead_in_s >= 0.0) || !(tail_s >= 0.0))
    throw dsp::InputError("acceleration profile: lead-in and tail must not be negative");
  dir_ = direction.normalized();
  double t = 0.0, x = 0.0, v = 0.0;
  for (const AccelSegment& s : segments_) {
    if (!(s.duration_s > 0.0) || !std::isfinite(s.accel_mm_s2))
      throw dsp::InputError("acceleration profile: a segment has no duration or no finite acceleration");
    t_start_.push_back(t), x_start_mm_.push_back(x), v_start_mm_s_.push_back(v);
    x += v * s.duration_s + 0.5 * s.accel_mm_s2 * s.duration_s * s.duration_s;
    v += s.accel_mm_s2 * s.duration_s;
    t += s.duration_s;
  }
  duration_ = lead_in_ + t + tail_s;
  triggers_ = {{0.0, dsp::trigger::program_start}, {duration_, dsp::trigger::program_end}};
}

std::size_t AccelProfileSetPoint::segment_at(double tau_s) const {
  const auto it = std::upper_bound(t_start_.begin(), t_start_.end(), tau_s);
  return static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - t_start_.begin()) - 1));
}

MotionState AccelProfileSetPoint::at(double t_s) const {
  MotionState m;
  const double tau = t_s - lead_in_;
  double x = 0.0, v = 0.0, a = 0.0;
  if (tau >= motion_s()) {
    const std::size_t k = segments_.size() - 1;
    const double d = segments_[k].duration_s;
    x = x_start_mm_[k] + v_start_mm_s_[k] * d + 0.5 * segments_[k].accel_mm_s2 * d * d;
  } else if (tau > 0.0) {
    const std::size_t k = segment_at(tau);
    const double d = tau - t_start_[k];
    a = segments_[k].accel_mm_s2;
    v = v_start_mm_s_[k] + a * d;
    x = x_start_mm_[k] + v_start_mm_s_[k] * d + 0.5 * a * d * d;
  }
  m.pos_mm = start_mm_ + dir_ * x;
  m.vel_mm_s = dir_ * v;
  m.acc_mm_s2 = dir_ * a;
  return m;
}

double AccelProfileSetPoint::accel_mm_s2(double t_s) const {
  const double tau = t_s - lead_in_;
  if (tau <= 0.0 || tau >= motion_s()) return 0.0;
  return segments_[segment_at(tau)].accel_mm_s2;
}

std::vector<std::pair<double, double>> AccelProfileSetPoint::move_spans_s() const {
  return {{lead_in_, lead_in_ + motion_s()}};
}

Eigen::Vector3d test_direction(const std::string& axis, const std::string& what) {
  if (axis == "x" || axis == "X") return Eigen::Vector3d::UnitX();
  if (axis == "y" || axis == "Y") return Eigen::Vector3d::UnitY();
  if (axis == "z" || axis == "Z") return Eigen::Vector3d::UnitZ();
  std::vector<double> v;
  std::stringstream ss(axis);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw dsp::InputError(what + ": '" + axis + "' is not x, y, z or dx,dy[,dz]");
    }
  }
  if (v.size() < 2 || v.size() > 3) throw dsp::InputError(what + ": '" + axis + "' is not x, y, z or dx,dy[,dz]");
  const Eigen::Vector3d d(v[0], v[1], v.size() == 3 ? v[2] : 0.0);
  if (!d.allFinite() || !(d.norm() > 0.0)) throw dsp::InputError(what + ": the direction '" + axis + "' has no length");
  return d.normalized();
}

}  // namespace eical::sim::nc
