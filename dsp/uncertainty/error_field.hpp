#pragma once
// What the measured relative path may be off by, as random draws for the uncertainty of
// every figure (GUM supplement 1: propagation of distributions). Three sources:
//   * the sensors' noise and bias walk between the supports. A draw simulates the error of
//     the integration with the white noise measured at rest in this run (RestNoise: the
//     Allan deviation of its quiet samples; the data sheet's density when it has none) and
//     the bias walk of the sensors' data sheet (run.toml's bias_walk_ug_per_rts), whatever the fusion
//     assumes, the supports' own errors (a standstill's residual velocity, a strip's
//     noise), and runs the pipeline's own smoother over it:
//     what the smoother leaves is one realisation of the path's error — also where the
//     fusion's model is not the truth (a simulation smoother for a mismatched model);
//   * the sensor model (sensor_model_covariance.hpp): each parameter's effect on the path,
//     E·Δx, c1·v, delay·v, α_b·ΔT, and a PSD strip's own offset, after the supports took
//     out what they see of it — the smoother is linear, so this is one pass per parameter
//     group over the path's own motion; a draw weighs them with parameters drawn from
//     the model's covariance;
//   * the reference points: their noise in the first (each fix with its strip's noise),
//     their offsets (the strips' position calibration) and their nonlinearity in the
//     second — a strip reads u (1 + nl (2u/L)²), nl within the data sheet's bound, the same
//     for every crossing of that strip, so its error follows where the spot crossed it.
// Everything runs on a coarse grid (coarse_schedule.hpp) in the sensors' time base and is
// interpolated onto the set-point's (the pipeline's delay alignment) where it is asked for.
// Draws are seeded and deterministic.
#include "dsp/core/sample_rate.hpp"
#include "dsp/core/sensor_model_covariance.hpp"
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/support_schedule.hpp"
#include "dsp/uncertainty/coarse_path.hpp"
#include "dsp/uncertainty/coarse_schedule.hpp"
#include "dsp/uncertainty/error_source.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace eical::dsp::uncertainty {

struct ErrorFieldInput {
  // The trace (the first constructor; the second takes it coarsened and leaves these null).
  const fusion::SupportSchedule* schedule = nullptr;  // as the pipeline used it (sensor time)
  const std::vector<std::int64_t>* sample_index = nullptr;
  const std::vector<Eigen::Vector3d>* pos_mm = nullptr;  // the measured path, aligned to the set-point
  const std::vector<Eigen::Vector3d>* vel_mm_s = nullptr;
  const std::vector<Eigen::Vector2d>* temp_c = nullptr;  // case temperature of table, head per trace sample (optional)
  double fs_hz = kDefaultFs_hz;
  double delay_samples = 0.0;  // aligned position = sensor position − delay
  fusion::ErrorModel model;    // the pipeline's fusion model
  Eigen::Vector3d start_bias_sigma_um_s2 = Eigen::Vector3d::Constant(20.0);
  double sensor_noise_ug_per_rthz[2] = {0.4, 0.4};  // the data sheet's, per sensor
  // head − table's white noise as measured at rest in this run (RestNoise; NaN: not
  // measured, the data sheet's densities then); two-sided, µg/√Hz.
  double rel_noise_ug_per_rthz = std::numeric_limits<double>::quiet_NaN();
  double bias_walk_ug_per_rts[2] = {0.0, 0.0};  // per sensor, as the data sheet specifies
  double g_mps2 = 9.81;
  SensorModelCovariance model_covariance;
  std::array<int, 3> owner{0, 0, 1};  // the sensor that carries each axis (−1: none)
  std::size_t max_coarse = 4000;      // coarse samples of the smoother passes
  // The run's strips (where each fix lies on its strip) and the bound of their
  // nonlinearity (drawn uniform within ±psd_nonlinearity per strip).
  std::vector<PsdSpec> psd;
  double psd_nonlinearity = DatasheetTolerance{}.psd_nonlinearity;
};

// The integration noise's share of a draw, which ErrorField::draw() makes first from the
// draw's generator: the error the pipeline's smoother leaves of simulated noise and bias walk,
// per coarse sample. It reads the coarse schedule and the model only, not the path, so it
// can be drawn before the path is known (a streamed analysis draws it beside its second
// pass). rng: the generator as the noise left it, for the rest of the draw.
struct NoiseDraw {
  std::vector<Eigen::Vector3d> error_um;
  std::mt19937_64 rng;
};
NoiseDraw draw_noise(const ErrorFieldInput& input, const CoarseSchedule& coarse, std::mt19937_64 rng);

// The noise bound's draw: only the sensors' white noise at the run's density, no bias walk
// or step, the strips' own noise and the standstills' residual velocity, fused by the
// smoother whose model is that truth (the optimal one, RTS for a linear Gaussian model)
// over the same supports. Per coarse sample, µm.
std::vector<Eigen::Vector3d> draw_noise_bound(const ErrorFieldInput& input, const CoarseSchedule& coarse,
                                              std::mt19937_64& rng);

class ErrorField {
 public:
  explicit ErrorField(const ErrorFieldInput& input);
  // The trace already coarsened (a streamed analysis): coarsen() with input.max_coarse's
  // block and the path a CoarsePathProbe collected over it; the same field.
  ErrorField(const ErrorFieldInput& input, CoarseSchedule coarse, const CoarsePath& path);

  // The coarse block of a trace of n samples.
  [[nodiscard]] static std::size_t block_for(std::size_t samples, std::size_t max_coarse) noexcept;

  // One draw of the path's error (µm per axis) at aligned trace positions (fractional
  // allowed).
  void draw(std::mt19937_64& rng, const std::vector<double>& at_pos, std::vector<Eigen::Vector3d>& error_um) const;
  // The same draw with its noise drawn already (draw_noise() of this field's input and
  // coarse schedule, from the generator draw() would have been given).
  void draw(NoiseDraw drawn, const std::vector<double>& at_pos, std::vector<Eigen::Vector3d>& error_um) const;
  // A draw of only the sources in `mask` (the budget); the integration's noise is drawn
  // only when the mask has it.
  void draw(std::mt19937_64& rng, const std::vector<double>& at_pos, std::vector<Eigen::Vector3d>& error_um,
            SourceMask mask) const;
  // A draw of the noise bound's error (draw_noise_bound()) at the same positions.
  void draw_bound(std::mt19937_64& rng, const std::vector<double>& at_pos,
                  std::vector<Eigen::Vector3d>& error_um) const;

  [[nodiscard]] std::size_t coarse_samples() const noexcept { return coarse_.sample_index.size(); }

 private:
  void build(const ErrorFieldInput& input, const CoarsePath& path);
  [[nodiscard]] double coarse_position(double at) const;
  void add_model(std::mt19937_64& rng, const std::vector<double>& at_pos, SourceMask mask,
                 std::vector<Eigen::Vector3d>& error_um) const;

  CoarseSchedule coarse_;
  ErrorFieldInput input_;  // what the noise draws read (its trace pointers cleared)
  double delay_ = 0.0;
  // Model responses per coarse sample, µm per unit parameter: per column j of E (all rows
  // i at once), the timing term (v·τ), per sensor its α_b, per PSD strip its offset.
  std::array<std::vector<Eigen::Vector3d>, 3> response_e_;
  std::array<bool, 3> column_moves_{false, false, false};
  std::vector<Eigen::Vector3d> response_timing_;
  std::array<std::vector<Eigen::Vector3d>, 2> response_tc_;
  std::vector<std::vector<Eigen::Vector3d>> response_strip_;
  std::vector<std::vector<Eigen::Vector3d>> response_strip_nl_;  // per strip, per unit nl
  std::array<int, 3> owner_{0, 0, 1};
  Eigen::MatrixXd model_factor_;  // θ = F z
  double strip_sigma_um_ = 0.0;
};

}  // namespace eical::dsp::uncertainty
