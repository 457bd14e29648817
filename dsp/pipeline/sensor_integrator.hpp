#pragma once
// One sensor's bias-free acceleration (machine axes, m/s²) → its velocity and displacement
// since the start of the motion, by the trapezoid rule (ch. 6.3.4), with the dynamic
// compensation applied at the chosen level (dynamic_comp.hpp). Per sample, no allocation.
#include "dsp/pipeline/dynamic_comp.hpp"

#include <Eigen/Core>

namespace eical::dsp {

struct SensorIntegrator {
  DynamicComp mode = DynamicComp::none;
  double c1_s = 0.0, c2_s2 = 0.0;
  double dt_nominal_s = 1e-4;  // the derivatives assume the nominal sampling step
  Eigen::Vector3d hist_mps2[3] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                  Eigen::Vector3d::Zero()};  // a[n−1..n−3]
  Eigen::Vector3d v_mps = Eigen::Vector3d::Zero();           // first integral (of A_kor at the acceleration level)
  Eigen::Vector3d x_m = Eigen::Vector3d::Zero();             // second integral
  Eigen::Vector3d integrand1_prev = Eigen::Vector3d::Zero(), integrand2_prev = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_out_m = Eigen::Vector3d::Zero(), v_out_mps = Eigen::Vector3d::Zero();  // compensated
  // Damping growing with the acceleration, ζ = ζ0 (1 + k|a|/g) (ch. 8.3.1): the sensor
  // drops a further (2ζ0 k/(ω0 g))·|a|·ȧ = c_amp·d(a|a|)/dt, given back at the velocity
  // (c_amp·a|a|) and the position (c_amp·∫a|a|dt) levels. c_amp = ζ0 k/(ω0 g), s³/m.
  double c_amp_s3_per_m = 0.0;
  Eigen::Vector3d amp_int_m2_s3 = Eigen::Vector3d::Zero(), amp_prev_m2_s4 = Eigen::Vector3d::Zero();

  SensorIntegrator() = default;
  SensorIntegrator(DynamicComp m, const DynamicCoefficients& c, double dt_s)
      : mode(m), c1_s(c.c1_s), c2_s2(c.c2_s2), dt_nominal_s(dt_s) {}

  // Second-order backward differences (exact for quadratics: no half-sample lag).
  [[nodiscard]] Eigen::Vector3d d1(const Eigen::Vector3d& a) const noexcept {
    return (3.0 * a - 4.0 * hist_mps2[0] + hist_mps2[1]) / (2.0 * dt_nominal_s);
  }
  [[nodiscard]] Eigen::Vector3d d2(const Eigen::Vector3d& a) const noexcept {
    return (2.0 * a - 5.0 * hist_mps2[0] + 4.0 * hist_mps2[1] - hist_mps2[2]) / (dt_nominal_s * dt_nominal_s);
  }

  // Start of the motion at rest: `a` is the first sample, `history` the three before it
  // (most recent first), all bias-free. Velocity and displacement start at zero.
  void start(const Eigen::Vector3d& a, const Eigen::Vector3d history[3]) noexcept {
    for (int k = 0; k < 3; ++k) hist_mps2[k] = history[k];
    v_mps.setZero(), x_m.setZero();
    integrand1_prev = mode == DynamicComp::acceleration_level ? Eigen::Vector3d(a + c1_s * d1(a) + c2_s2 * d2(a)) : a;
    integrand2_prev =
        mode == DynamicComp::velocity_level ? Eigen::Vector3d(c1_s * a + c2_s2 * d1(a)) : Eigen::Vector3d::Zero();
    x_out_m.setZero(), v_out_mps = integrand2_prev;
    amp_int_m2_s3.setZero(), amp_prev_m2_s4 = a.cwiseProduct(a.cwiseAbs());
    if (mode != DynamicComp::none) v_out_mps += c_amp_s3_per_m * amp_prev_m2_s4;
    push(a);
  }

  void step(const Eigen::Vector3d& a, double dt_s) noexcept {
    // First integral: A_s, or A_kor = A_s + c1·Ȧ + c2·Ä at the acceleration level (6-33).
    const Eigen::Vector3d i1 =
        mode == DynamicComp::acceleration_level ? Eigen::Vector3d(a + c1_s * d1(a) + c2_s2 * d2(a)) : a;
    v_mps += 0.5 * (i1 + integrand1_prev) * dt_s;
    integrand1_prev = i1;
    // Second integral: V, or V_kor = V_s + c1·A_s + c2·Ȧ_s at the velocity level (6-34).
    const Eigen::Vector3d i2 =
        mode == DynamicComp::velocity_level ? Eigen::Vector3d(v_mps + c1_s * a + c2_s2 * d1(a)) : v_mps;
    x_m += 0.5 * (i2 + integrand2_prev) * dt_s;
    integrand2_prev = i2;
    if (mode == DynamicComp::position_level) {
      x_out_m = x_m + c1_s * v_mps + c2_s2 * a;  // (6-38)
      v_out_mps = v_mps + c1_s * a;              // the c2·jerk term is left out of the velocity: it is noise there
    } else {
      x_out_m = x_m;
      v_out_mps = i2;
    }
    if (c_amp_s3_per_m != 0.0 && mode != DynamicComp::none) {
      const Eigen::Vector3d aa = a.cwiseProduct(a.cwiseAbs());
      amp_int_m2_s3 += 0.5 * (aa + amp_prev_m2_s4) * dt_s;
      amp_prev_m2_s4 = aa;
      x_out_m += c_amp_s3_per_m * amp_int_m2_s3, v_out_mps += c_amp_s3_per_m * aa;
    }
    push(a);
  }

 private:
  void push(const Eigen::Vector3d& a) noexcept {
    hist_mps2[2] = hist_mps2[1], hist_mps2[1] = hist_mps2[0], hist_mps2[0] = a;
  }
};

}  // namespace eical::dsp
