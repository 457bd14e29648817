#pragma once
// The uncertainty of the sensor model the pipeline compensates with: GUM type B from the
// data sheet's tolerances, or type A from an on-site identification (the calibration
// file's covariance). One parameter vector for both sensors and the DAQ:
//
//   E^s_ij   s = table, head; i, j = x, y, z     measured = (I + E)·true in machine axes
//            (scale on the diagonal, mounting and cross-axis terms off it)   index 9s + 3i + j
//   c1^s     error of the damping term 2ζ/ω0 of sensor s (6-38), s          index 18 + s
//   delay    error of the DAQ group delay, s                                 index 20
//   α_b^s_i  error of sensor s's bias temperature coefficient along machine
//            axis i (6-7), µg/°C (the data sheet gives ±100 µg/°C: its sign
//            is not known)                                                  index 21 + 3s + i
//
// What they do to the relative path (head − table): E^s_ij adds E·Δx_j along axis i for
// the axes j sensor s carries; c1^s adds c1·v_i along the axes it carries; the delay adds
// delay·v_i along every axis; α_b adds a bias that follows the sensor's case temperature
// since the rest window. The supports then take out what they can
// (uncertainty/error_field.hpp).
#include "dsp/core/run_meta.hpp"

#include <Eigen/Core>

#include <array>
#include <string>

namespace eical::dsp {

inline constexpr int kModelParameters = 27;
inline constexpr int kDelayIndex = 20;
constexpr int error_index(int sensor, int i, int j) noexcept { return 9 * sensor + 3 * i + j; }
constexpr int damping_index(int sensor) noexcept { return 18 + sensor; }
constexpr int tc_bias_index(int sensor, int i) noexcept { return 21 + 3 * sensor + i; }
// "table.E_xy", "head.c1_s", "daq.delay_s", "table.tc_bias_x_ug_per_c".
std::string parameter_name(int p);
// The index of a parameter name, −1 when it is none of them.
int parameter_index(const std::string& name);

using ModelMatrix = Eigen::Matrix<double, kModelParameters, kModelParameters>;

struct SensorModelCovariance {
  ModelMatrix covariance = ModelMatrix::Zero();  // standard uncertainties², units of the parameters
  std::string source = "datasheet";              // "datasheet" or the calibration's method
  // A PSD strip's own systematic error (nonlinearity, the spot's shape): µm, σ per strip.
  double psd_offset_sigma_um = 0.1;
  [[nodiscard]] double sigma(int p) const { return std::sqrt(std::max(0.0, covariance(p, p))); }
};

// The data sheet's tolerances (SF3000L, the sample runs' truth.toml: what `eical simulate
// --background` draws), uniform within ±a, so u = a/√3 (GUM 4.3.7).
// Gravity (1 g along machine z) turns some of the static model's terms (6-4) into scale
// errors: k_zx·a_z·a_x and k_zy·a_z·a_y act on x and y as a scale of k_zx·g, and on the
// vertical axis k2, k3 act as a scale of 2·k2·g and 3·k3·g² (their slope at 1 g).
struct DatasheetTolerance {
  double scale = 400e-6;          // k1 per axis, relative
  double cross2_g_per_g2 = 2e-4;  // k_zx, k_zy: on x and y a scale error with gravity
  double k2_k3_relative = 0.05;   // k2, k3 within 5 % of the data sheet's
  double cross_g_per_g = 2e-4;    // cross-axis sensitivity
  double mounting_rad = 3e-4;     // mounting rotation about each axis
  double f0_relative = 0.01;      // resonance
  double zeta = 0.01;             // damping
  double delay_samples = 0.0;     // the DAQ's linear-phase FIR: its delay is exact by design
  // The noise density of a unit about the data sheet's typical value: 0.3–0.5 µg/√Hz for
  // the SF3000L's 0.4 (what a run's rest windows are checked against).
  double noise_density_relative = 0.25;
  double tc_bias_ug_per_c =
      210.0;  // ±100 µg/°C of unknown sign, 85–110 per unit: compensating with +100 errs by up to 210
  // A PSD strip's own nonlinearity, u_meas = u (1 + nl (2u/L)²), |nl| within this (relative
  // at the strip's end, 0.5 µm on a 10 mm strip; what `eical simulate --background` draws).
  double psd_nonlinearity = 1e-4;
};

// Per machine axis, σ (s) of the sensor model's timing: the damping term of the sensor that
// carries the axis (owner: 0 table, 1 head, −1 none) and the DAQ's delay
// (fusion::ErrorModel::timing_uncertainty_s).
std::array<double, 3> timing_sigma_s(const SensorModelCovariance& c, const std::array<int, 3>& owner);

// The covariance the data sheet gives (independent parameters).
SensorModelCovariance datasheet_covariance(const SensorSpec sensors[2], double fs_hz,
                                           const DatasheetTolerance& tolerance = {});

}  // namespace eical::dsp
