#pragma once
// Jerk-limited rest-to-rest motion along a path of length L (the NC's feed profile):
// jerk ±j_max, acceleration up to a_max, cruise at v_max. When L is too short for the
// cruise speed the peak speed is lowered until the profile fits. Seven phases
// (jerk, constant acceleration, jerk, cruise, and the mirror), evaluated analytically.
namespace eical::sim::nc {

struct PathState {
  double s = 0.0;  // path position (mm)
  double v = 0.0;  // mm/s
  double a = 0.0;  // mm/s²
  double j = 0.0;  // mm/s³
};

class SCurve {
 public:
  SCurve() = default;
  // length_mm ≥ 0; v, a, j limits > 0 (mm/s, mm/s², mm/s³).
  SCurve(double length_mm, double v_max, double a_max, double j_max);

  [[nodiscard]] double duration_s() const { return duration_; }
  [[nodiscard]] double length_mm() const { return length_; }
  [[nodiscard]] double peak_speed() const { return v_peak_; }
  [[nodiscard]] double peak_accel() const { return a_peak_; }
  [[nodiscard]] PathState at(double t_s) const;
  // Time at which the path position reaches s (bisection on the monotone s(t)).
  [[nodiscard]] double time_at(double s_mm) const;

 private:
  [[nodiscard]] PathState accel_phase(double t) const;  // 0 ≤ t ≤ t_acc_, from rest to v_peak
  double length_ = 0.0, v_peak_ = 0.0, a_peak_ = 0.0, j_ = 1.0;
  double t_j_ = 0.0, t_a_ = 0.0;  // jerk phase, constant-acceleration phase
  double t_acc_ = 0.0, t_cruise_ = 0.0, duration_ = 0.0, s_acc_ = 0.0;
};

}  // namespace eical::sim::nc
