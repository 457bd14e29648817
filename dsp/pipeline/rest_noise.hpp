#pragma once
// The white noise of the relative acceleration head − table, measured where the machine
// is still: the Allan deviation of the quiet samples at one cluster time τ. For white
// noise of two-sided density n (the run format's convention: σ = n·√fs per sample), the
// one-sided PSD is 2n² and AVAR(τ) = n²/τ (IEEE 952). τ is long against the
// sensor's PT2 and the DAQ's anti-alias filter (their response is then flat: at 5 ms and a
// 1 kHz PT2 the filters bias AVAR by about 1.5 %), short enough that a rest of 0.1 s gives
// twenty clusters. The deviation is taken from the median of the squared cluster
// differences (a settling transient or a knock in a rest window is an outlier there, not a
// larger noise): for Gaussian differences median(d²) = 0.4549·2·AVAR.
//
// What the uncertainty's draws simulate as the integration noise comes from here (the
// data sheet's density only when the run holds too few quiet clusters), and it is checked
// against the data sheet (figure_uncertainty.hpp).
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace eical::dsp {

struct RestNoise {
  // Two-sided white noise density of head − table per machine axis, µg/√Hz (NaN: not
  // measured): √(n_table² + n_head²) for independent sensors.
  Eigen::Vector3d density_ug_rthz = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::size_t differences = 0;  // cluster differences per axis behind it
  double tau_s = 0.0;
  double quiet_s = 0.0;  // seconds of quiet samples read
  // Relative standard uncertainty of a density from `differences` (of the median-based
  // estimate: about 1.7/√N on the variance, half that on the density).
  [[nodiscard]] double relative_u() const noexcept;
  [[nodiscard]] bool measured() const noexcept { return differences >= kMinDifferences; }
  static constexpr std::size_t kMinDifferences = 8;
};

class RestNoiseMeter {
 public:
  // capacity: cluster differences kept per axis (reserved here, none allocated later).
  RestNoiseMeter(double fs_hz, double g_mps2, std::size_t capacity = 8192);
  void sample(const Eigen::Vector3d& rel_mps2) noexcept;  // a quiet sample
  void gap() noexcept;                                    // the quiet stretch ended
  void reset() noexcept;
  [[nodiscard]] RestNoise result() const;

  static constexpr double kTauS = 0.005;

 private:
  double g_mps2_ = 9.81;
  std::size_t m_ = 50;  // samples per cluster
  double tau_s_ = kTauS, dt_s_ = 1e-4;
  std::size_t in_cluster_ = 0, quiet_samples_ = 0;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero(), prev_mean_ = Eigen::Vector3d::Zero();
  bool have_prev_ = false;
  std::array<std::vector<double>, 3> d2_;
};

}  // namespace eical::dsp
