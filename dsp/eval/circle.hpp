#pragma once
// Circular test evaluation (ISO 230-4 figures) from the measured relative path.
//
// The revolutions are the segments between consecutive M102 marks (a circle program has
// one before every revolution and one after the last; ramp-in and ramp-out are left out,
// so the feed is constant). Each revolution gets its own least-squares centre: doubly
// integrated acceleration drifts slowly, and a centre per revolution absorbs that drift
// the way a ballbar's physical pivot does (one centre over five revolutions leaves about
// 10 µm RMS of drift in the radius at 0.4 µg/√Hz; per revolution about 3 µm).
//
// Radius deviation = distance from the revolution's LSQ centre − nominal radius. Over all
// revolutions: mean radius deviation, G = max − min of the radius deviation (LSQ
// reference, ISO 230-4 circular deviation), F_max / F_min (radial deviation from the
// nominal radius). Hysteresis H needs both directions (combine()).
#include "dsp/core/float_limits.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace eical::dsp::eval {

struct CircleInput {
  std::vector<Eigen::Vector2d> pos_mm;      // measured, in the plane (axis a, axis b)
  std::vector<std::int64_t> sample_index;   // same length
  std::vector<std::int64_t> segment_marks;  // sample indices of the M102 triggers
  // Explicit [begin, end) sample-index ranges of the revolutions (circle_segments.hpp);
  // when non-empty they replace the consecutive marks (a "both" program has a stretch
  // between the directions that is no revolution).
  std::vector<std::pair<std::int64_t, std::int64_t>> segments;
  Eigen::Vector2d center_mm = Eigen::Vector2d::Zero();  // nominal
  double radius_mm = 10.0;                              // nominal
  std::string direction = "ccw";
  bool keep_trace = true;  // false: the figures only, no per-point trace (the uncertainty's draws)
};

struct CircleTrace {
  std::vector<double> angle_deg;  // 0..360 about the revolution's centre
  std::vector<double> radius_deviation_um;
  std::vector<std::string> direction;  // per point, for combined traces
  std::vector<int> revolution;         // revolution or arc index within its direction
  // 1: every point. n > 1: the points whose index in the (combined) trace is a multiple
  // of n (long runs evaluated as they stream keep only what the plots show).
  std::size_t stride = 1;
};

struct CircleResult {
  std::string direction;
  int revolutions = 0;
  double radius_mean_deviation_um = 0.0;
  double circular_deviation_G_um = 0.0;
  std::optional<double> circular_hysteresis_H_um;  // only with both directions
  double radial_deviation_F_max_um = 0.0, radial_deviation_F_min_um = 0.0;
  double arc_deg = 360.0;                   // < 360: partial arc, evaluated about the programmed centre
  std::vector<Eigen::Vector2d> centers_mm;  // per revolution (partial arc: the programmed centre)
  std::vector<double> radii_mm;
  CircleTrace trace;
  std::size_t points = 0;  // radius deviations evaluated (all, whatever the trace keeps)
  // The largest and smallest radius deviation of each direction's own points (counter-
  // clockwise, clockwise; ±inf: not run): G per direction, whatever the trace keeps.
  std::array<double, 2> direction_F_max_um{-kInf, -kInf}, direction_F_min_um{kInf, kInf};
  // Sum and count of the radius deviations per 1° of angle (H of combine()).
  std::array<double, 360> deviation_sum_by_deg{}, points_by_deg{};
  // G of the averaged revolution of each direction (counter-clockwise, clockwise): max −
  // min over 1° of the mean radius deviation of its revolutions. The machine's shape
  // repeats each revolution, the noise does not: with N revolutions its share falls as
  // 1/√N, where ISO 230-4's G over all revolutions keeps the worst of them. NaN: fewer
  // than two full revolutions in that direction, or a degree no revolution crossed.
  std::array<double, 2> direction_averaged_G_um{kNaN, kNaN};
};

// Geometric least-squares circle (Kasa algebraic start, Gauss–Newton on the distances).
struct CircleFit {
  Eigen::Vector2d center;
  double radius;
};
CircleFit fit_circle(const std::vector<Eigen::Vector2d>& points);

// Throws InputError when there are fewer than two M102 marks inside the trace or a
// revolution has too few points.
CircleResult evaluate_circle(const CircleInput& input);

// One direction's revolutions (or partial arcs) evaluated as their samples arrive in
// order, one revolution at a time: a full revolution is fitted when it ends, so memory
// holds one revolution, never the whole trace. evaluate_circle() and evaluate_arc() feed
// it from stored traces; the streamed analysis (dsp/stream) as the trace goes by.
class CircleAccumulator {
 public:
  struct Options {
    Eigen::Vector2d center_mm = Eigen::Vector2d::Zero();  // nominal (partial arc: the programmed centre)
    double radius_mm = 10.0;
    std::string direction = "ccw";
    double arc_deg = 360.0;  // below 360: partial arcs about the programmed centre (circle_arc.hpp)
    // The trace keeps the points whose index offset + i (i: this direction's own count) is
    // a multiple of trace_stride (combine() appends directions in order).
    std::size_t trace_stride = 1, trace_offset = 0;
    bool keep_trace = true;  // false: no per-point trace at all (the figures need none)
  };
  explicit CircleAccumulator(Options o);
  // A revolution (arc) starts; expected_samples (when known) sizes its buffer at once.
  void begin(std::size_t expected_samples = 0);
  // A sample of it; throws InputError on a position that is not finite.
  void add(std::int64_t sample_index, const Eigen::Vector2d& pos_mm);
  // It ends: fitted and evaluated; throws InputError when it has too few samples.
  void end();
  // Throws InputError when no revolution was evaluated.
  [[nodiscard]] CircleResult result() const;
  // The radius deviations (µm) of the revolution that ended last, in order.
  [[nodiscard]] const std::vector<double>& revolution_deviations() const noexcept { return last_dev_; }

 private:
  void put(const Eigen::Vector2d& d, double dev_um);
  Options o_;
  CircleResult r_;
  std::vector<Eigen::Vector2d> pts_;  // the open revolution (full circles)
  std::vector<double> last_dev_;
  std::size_t n_here_ = 0;  // samples of the open arc
  double sum_here_ = 0.0, sum_dev_ = 0.0, dmax_ = -kInf, dmin_ = kInf;
  int open_ = -1;  // index of the open revolution, -1 when none
};

// Both directions (ISO 230-4 H): G and F over both, H = max over 1° angle bins of |mean dev ccw − mean dev cw|.
CircleResult combine(const CircleResult& a, const CircleResult& b);

}  // namespace eical::dsp::eval
