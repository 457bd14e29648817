#pragma once
// Static compensation of one triplex sensor (ch. 6.3, Bild 6-19): ADC counts → volts → g
// with the temperature-compensated scale and bias (6-16), the inverse of the static model's
// nonlinearity and cross terms (6-4, 6-17), and the 3×3 correction of mounting
// misalignment (6-18) into machine axes. The rest-window bias of the pipeline removes what
// the data-sheet bias misses (and gravity).
//
// The static model (6-4) a sensor follows (and the simulator generates):
//   U = k1(T) · (v + k2 v² + k3 v³ + Σ_j≠i kx_ij v_j + Σ_j≠i kxx_ij v_i v_j + bias(T))
//   k1(T) = k1 (1 + α_k ΔT),  bias(T) = bias + α_b ΔT                  (6-7, 6-8)
// Inverting it: u = U / k1(T) − bias(T) (6-16), then v from u = M(v) by the iteration
//   r = u − M(v),   v ← v + (K⁻¹ − diag(s))·r,   K = I + kx,  s_i = 2 k2_i v_i + 3 k3_i v_i²,
// starting at v = u: a Newton step with the Jacobian I + kx + diag(s) inverted to first
// order. Its first step is (6-17) (a_kor = a − k2 a² − k3 a³, and − kx a) plus the next
// order; each further one shrinks the error by ≈ max(s², s·|kx|, |kxx| v) — 6e-5 at 1 g with
// the data-sheet k2, k3 — so three steps leave < 1e-11 g up to ±2 g (tested). The thesis'
// (6-17) alone misses 2 k2² ≈ 5 µg at 1 g.
#include "dsp/core/run_meta.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace eical::dsp {

// What a calibration adds to the data sheet (defaults: the data sheet, nothing added).
struct StaticCalibration {
  // (6-4) cross-axis terms, g per g: row = sensor axis responding, column = axis across it.
  Eigen::Matrix3d cross_g_per_g = Eigen::Matrix3d::Zero();
  // (6-4) product terms kxx_ij v_i v_j, g per g² (diagonal unused).
  Eigen::Matrix3d cross2_g_per_g2 = Eigen::Matrix3d::Zero();
  // (6-18) mounting misalignment: true sensor → machine = data-sheet to_machine · mounting.
  Eigen::Matrix3d mounting = Eigen::Matrix3d::Identity();
};

struct StaticCompOptions {
  bool temperature = true;   // (6-16) with the frames' case temperature
  bool nonlinearity = true;  // (6-17) k2, k3
};

inline constexpr int kStaticCompIterations = 3;

struct StaticComp {
  Eigen::Vector3d g_per_count = Eigen::Vector3d::Ones();  // lsb / k1 at the reference temperature
  double offset_counts = 0.0;
  Eigen::Vector3d bias_g = Eigen::Vector3d::Zero();
  double tc_k1_per_c = 0.0;      // α_k
  double tc_bias_g_per_c = 0.0;  // α_b
  double temp_ref_c = 20.0;
  Eigen::Vector3d k2_g_per_g2 = Eigen::Vector3d::Zero(), k3_g_per_g3 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cross_g_per_g = Eigen::Matrix3d::Zero(), cross2_g_per_g2 = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d cross_inverse = Eigen::Matrix3d::Identity();          // (I + kx)⁻¹
  bool iterate = false;                                                 // any nonlinear or cross term to invert
  Eigen::Matrix3d to_machine_mps2_per_g = Eigen::Matrix3d::Identity();  // to_machine · mounting · g

  StaticComp() = default;
  StaticComp(const SensorSpec& spec, const Acquisition& acq, const Site& site, const StaticCalibration& cal = {},
             const StaticCompOptions& options = {});

  // u = U/k1(T) − bias(T) in g, sensor axes (6-16).
  [[nodiscard]] Eigen::Vector3d scaled_g(const std::int32_t counts[3], double temp_c) const noexcept {
    const double dt_c = temp_c - temp_ref_c;
    const double inv_scale = 1.0 / (1.0 + tc_k1_per_c * dt_c);
    Eigen::Vector3d u;
    for (int i = 0; i < 3; ++i)
      u[i] = (static_cast<double>(counts[i]) - offset_counts) * g_per_count[i] * inv_scale -
             (bias_g[i] + tc_bias_g_per_c * dt_c);
    return u;
  }

  // The model M(v) of (6-4) without k1 and bias, g.
  [[nodiscard]] Eigen::Vector3d model(const Eigen::Vector3d& v) const noexcept {
    Eigen::Vector3d u;
    for (int i = 0; i < 3; ++i) {
      double m = v[i] + k2_g_per_g2[i] * v[i] * v[i] + k3_g_per_g3[i] * v[i] * v[i] * v[i];
      for (int j = 0; j < 3; ++j)
        if (j != i) m += cross_g_per_g(i, j) * v[j] + cross2_g_per_g2(i, j) * v[i] * v[j];
      u[i] = m;
    }
    return u;
  }

  // The sensed acceleration v (g, sensor axes) whose model output is u (6-17 and cross terms).
  [[nodiscard]] Eigen::Vector3d invert_model(const Eigen::Vector3d& u) const noexcept {
    if (!iterate) return u;
    Eigen::Vector3d v = u;
    for (int it = 0; it < kStaticCompIterations; ++it) {
      const Eigen::Vector3d r = u - model(v);
      const Eigen::Vector3d slope =
          2.0 * k2_g_per_g2.cwiseProduct(v) + 3.0 * k3_g_per_g3.cwiseProduct(v.cwiseProduct(v));
      v += cross_inverse * r - slope.cwiseProduct(r);
    }
    return v;
  }

  // Specific force in machine axes, m/s².
  [[nodiscard]] Eigen::Vector3d apply(const std::int32_t counts[3], double temp_c) const noexcept {
    return to_machine_mps2_per_g * invert_model(scaled_g(counts, temp_c));
  }
};

// The sensor model (6-4) forward, g in → g out (sensor axes, before k1 and bias): for
// tests and for identification residuals.
Eigen::Vector3d static_model_g(const Eigen::Vector3d& v_g, const SensorSpec& spec, const StaticCalibration& cal);

}  // namespace eical::dsp
