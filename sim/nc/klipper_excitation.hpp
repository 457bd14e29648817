#pragma once
// Klipper's resonance test (Klipper3d/klipper, klippy/extras/resonance_tester.py) as
// piecewise-constant acceleration along one direction, and the set-point that motion is.
// `eical import klipper` reconstructs the set-point of a capture with it and the
// simulator's sweep runs the same motion, so the two agree by construction.
//
// Current Klipper (VibrationPulseTestGenerator.gen_test, SweepingVibrationsTestGenerator,
// ResonanceTestExecutor.run_test; defaults min_freq 5, max_freq 200, accel_per_hz 60,
// hz_per_sec 1, sweeping_accel 400, sweeping_period 1.2):
//   freq = freq_start; s = +1; while freq <= freq_end + 1e-6:
//     t_seg = 0.25/freq; +s·accel_per_hz·freq for t_seg, then −s·accel_per_hz·freq for
//     t_seg; freq += 2·t_seg·hz_per_sec; s = −s
//   The sweep adds ±sweeping_accel, switching sign first after period·√2/8, then after
//   period·(√2/8 + 1/4), then every period/2. The executor turns every entry into one
//   constant-acceleration move (input shaping off, minimum cruise ratio 0) and, when the
//   head still moves at the end, stops it at the printer's max_accel.
// Older Klipper (VibrationPulseTest.run_test; max_freq 10000/75 = 133.33 Hz, accel_per_hz
// 75, no sweep): per frequency step M204 S = accel_per_hz·freq and two moves of
// L = ½·accel·t_seg² at max_v = accel·t_seg, out and back to the centre, the next step out
// on the other side. A move out ends in a reversal (junction speed 0); the move back meets
// the next move out in a straight line, so the lookahead lets the head pass the centre at
// max_v: a square wave of ±accel, t_seg per move, the first and last moves triangles
// (from and to rest). 5 → 133 Hz at 1 Hz/s runs about 128 s, as real captures last.
#include "sim/nc/set_point.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace eical::sim::nc {

// Constant acceleration along the test direction for a while.
struct AccelSegment {
  double duration_s = 0.0;
  double accel_mm_s2 = 0.0;
};

struct KlipperTest {
  double freq_start_hz = 5.0;
  double freq_end_hz = 200.0;
  double accel_per_hz = 60.0;  // mm/s² per Hz
  double hz_per_sec = 1.0;
  double sweeping_accel_mm_s2 = 400.0;  // 0 (or a period of 0): no slow sweep
  double sweeping_period_s = 1.2;
  bool legacy_moves = false;         // the older executor (moves out and back through the centre)
  double stop_accel_mm_s2 = 5000.0;  // the printer's max_accel: the final stop after a sweep

  // Klipper's defaults today, and those of the older releases (see above).
  static KlipperTest current();
  static KlipperTest legacy();
  // "" when the parameters are usable, else why not (Klipper's own limits: freq ≥ 1 Hz,
  // freq_end ≥ freq_start, freq_end ≤ 300 Hz, 0 < hz_per_sec ≤ 2, accel_per_hz > 0; and
  // eical's: a sweep of at most kMaxSweepS, a sweeping period of 0 or at least 0.1 s).
  static constexpr double kMaxSweepS = 3600.0;
  [[nodiscard]] std::string invalid_reason() const;
};

// The test as Klipper executes it: ends at rest.
std::vector<AccelSegment> klipper_segments(const KlipperTest& test);

// A set-point that rests at `start_mm` for `lead_in_s`, runs `segments` along the unit
// `direction` (mm, mm/s, mm/s² exact: piecewise quadratic), then rests for `tail_s`.
// M101 at t = 0 and M103 at the end.
class AccelProfileSetPoint final : public SetPoint {
 public:
  AccelProfileSetPoint(std::vector<AccelSegment> segments, const Eigen::Vector3d& direction,
                       const Eigen::Vector3d& start_mm, double lead_in_s = 0.0, double tail_s = 0.0);

  [[nodiscard]] MotionState at(double t_s) const override;
  [[nodiscard]] const std::vector<TimedTrigger>& triggers() const override { return triggers_; }
  [[nodiscard]] double duration_s() const override { return duration_; }
  [[nodiscard]] std::vector<std::pair<double, double>> move_spans_s() const override;

  // Acceleration along the direction (mm/s²) at t: the commanded excitation.
  [[nodiscard]] double accel_mm_s2(double t_s) const;
  [[nodiscard]] double motion_s() const {
    return t_start_.empty() ? 0.0 : t_start_.back() + segments_.back().duration_s;
  }
  [[nodiscard]] double lead_in_s() const { return lead_in_; }
  [[nodiscard]] const Eigen::Vector3d& direction() const { return dir_; }

 private:
  [[nodiscard]] std::size_t segment_at(double tau_s) const;

  std::vector<AccelSegment> segments_;
  std::vector<double> t_start_, x_start_mm_, v_start_mm_s_;  // per segment, along the direction
  Eigen::Vector3d dir_, start_mm_;
  double lead_in_, duration_;
  std::vector<TimedTrigger> triggers_;
};

// A test direction as Klipper's AXIS parameter gives it: "x", "y", "z" or "dx,dy[,dz]"
// (normalised). Throws InputError naming `what` for anything else.
Eigen::Vector3d test_direction(const std::string& axis, const std::string& what);

}  // namespace eical::sim::nc
