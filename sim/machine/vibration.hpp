#pragma once
// Structural vibration on the internal grid.
//  * DriveModeResponse: a mode excited by the axes' commanded acceleration,
//    m'' + 2ζω m' + ω² m = gain·a_cmd per machine axis — the machine rocking on its
//    foundation (common to head and table) or the head swinging against the table
//    (differential: real relative motion).
//  * CommonAcceleration: floor and drive tones plus band-limited broadband noise that
//    move head and table together (absolute acceleration only).
#include "sim/scenario.hpp"
#include "sim/sensor/pt2.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <random>
#include <vector>

namespace eical::sim {

class DriveModeResponse {
 public:
  DriveModeResponse(const DriveMode& mode, double step_s);
  // Displacement (mm) of the mode for the commanded acceleration (mm/s²) at this sample.
  Eigen::Vector3d step(const Eigen::Vector3d& cmd_acc_mm_s2) noexcept;
  [[nodiscard]] bool on() const noexcept { return on_; }

 private:
  Eigen::Vector3d gain_over_w2_;
  std::optional<Pt2> axis_[3];
  Eigen::Vector3d prev_ = Eigen::Vector3d::Zero();
  bool on_;
};

// Second-order Butterworth section (bilinear transform), direct form II transposed.
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0, z1 = 0, z2 = 0;
  static Biquad lowpass(double fc_hz, double fs_hz);
  static Biquad highpass(double fc_hz, double fs_hz);
  double step(double x) noexcept {
    const double y = b0 * x + z1;
    z1 = b1 * x - a1 * y + z2;
    z2 = b2 * x - a2 * y;
    return y;
  }
};

// The broadband part is generated at 1/decimation of the internal rate (its band ends far
// below that Nyquist frequency) and interpolated linearly: a tenth of the random numbers.
class CommonAcceleration {
 public:
  CommonAcceleration(const CommonVibration& vib, double g_mps2, double step_s, int decimation, std::uint64_t seed);
  // Absolute acceleration (m/s², machine axes) shared by head and table at the next
  // internal sample (the first call is t = 0).
  Eigen::Vector3d step() noexcept;

 private:
  const CommonVibration& vib_;
  double g_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  Biquad hp_[3], lp_[3];
  Eigen::Vector3d broadband_scale_ = Eigen::Vector3d::Zero();  // m/s² per unit white sample
  bool broadband_ = false;
  int decimation_ = 1, phase_ = 0;
  Eigen::Vector3d from_ = Eigen::Vector3d::Zero(), to_ = Eigen::Vector3d::Zero();
  // Tones as phasors rotated by a fixed angle per step (no sine per sample); re-normalised
  // now and then against rounding drift.
  std::vector<std::array<double, 4>> phasor_;  // cos, sin, cos step, sin step
  std::size_t steps_ = 0;
};

}  // namespace eical::sim
