// The fusion's hand-written rows and transition against what they linearise or discretise,
// as basalt checks its Jacobians: each support's row (dsp/fusion/support_rows.hpp) against
// central differences of its measurement function, the error model's F against central
// differences of the continuous model's flow, and F and Q against Van Loan's matrix
// exponential of the continuous model. A wrong entry fails here.
#include "dsp/fusion/axis_filter.hpp"
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/forward_filter.hpp"
#include "dsp/fusion/support_rows.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include <numeric>
#include <string>
#include <vector>

namespace eical::dsp::fusion {
namespace {

template <class F>
StateRow numeric_row(const F& f, const State& e, double step = 1e-3) {
  StateRow h;
  for (int i = 0; i < kStates; ++i) {
    State ep = e, em = e;
    ep[i] += step, em[i] -= step;
    h[i] = (f(ep) - f(em)) / (2.0 * step);
  }
  return h;
}

void expect_row(const StateRow& analytic, const StateRow& numeric, const std::string& what) {
  for (int i = 0; i < kStates; ++i)
    EXPECT_NEAR(analytic[i], numeric[i], 1e-9 * (1.0 + std::abs(numeric[i]))) << what << ", state " << i;
}

TEST(FusionJacobian, EverySupportRowIsTheGradientOfItsMeasurementFunction) {
  for (const State& e : {State{1.5, -2.0, 30.0, 120.0, 2.5}, State{-40.0, 0.3, -7.0, -35.0, -1.2}}) {
    expect_row(observe::zupt_row(), numeric_row([](const State& s) { return observe::zupt(s); }, e), "zupt");
    expect_row(observe::nbs_row(), numeric_row([](const State& s) { return observe::nbs(s); }, e), "nbs");
    for (const double way_mm : {0.0, 87.5, -240.0})
      for (const double vel_mm_s : {0.0, 66.7, -150.0})
        expect_row(observe::cupt_row(way_mm, vel_mm_s),
                   numeric_row([&](const State& s) { return observe::cupt(s, way_mm, vel_mm_s); }, e),
                   "cupt at " + std::to_string(way_mm) + " mm, " + std::to_string(vel_mm_s) + " mm/s");
    // A ringing standstill's window: 0.1 s at 1 kHz ending at sample k, and an uneven one.
    std::vector<double> even(100);
    for (std::size_t i = 0; i < even.size(); ++i) even[i] = static_cast<double>(i) * 1e-3;
    for (const std::vector<double>& ago_s : {even, std::vector<double>{0.0, 0.002, 0.011, 0.05}}) {
      const double lag_s = std::accumulate(ago_s.begin(), ago_s.end(), 0.0) / static_cast<double>(ago_s.size());
      expect_row(observe::velocity_mean_row(lag_s),
                 numeric_row([&](const State& s) { return observe::window_mean_velocity(s, ago_s); }, e),
                 "velocity mean over " + std::to_string(ago_s.size()) + " samples");
    }
  }
}

TEST(FusionJacobian, TheFilterUpdatesWithTheseRows) {
  // Each support moves the state along its row's gain: with P = I the update of z = h·e
  // changes e by h/(h·h + r) times the innovation.
  ErrorModel m;
  m.scale_state_ppm = {300.0, 0.0, 0.0};
  const State e0{1.0, 2.0, 3.0, 4.0, 5.0};
  const auto check = [&](const StateRow& h, double z, double r, auto&& apply, const std::string& what) {
    ForwardFilter f;
    f.start(m, Vec3::Constant(1.0));
    f.axis[0].e = e0, f.axis[0].P = StateCov::Identity();
    apply(f);
    const double nu = z - h.dot(e0);
    const State expected = e0 + h.transpose() / (h.dot(h) + r) * nu;
    for (int i = 0; i < kStates; ++i) EXPECT_NEAR(f.axis[0].e[i], expected[i], 1e-12) << what << ", state " << i;
  };
  const double zs = m.zupt_sigma_um_s, ns = m.nbs_sigma_um_s;
  check(
      observe::zupt_row(), 2.5, zs * zs,
      [](ForwardFilter& f) { f.velocity_supports(schedule_flag::rest, Vec3(2.5, 0.0, 0.0), ErrorModel{}); }, "zupt");
  check(
      observe::nbs_row(), 2.5, ns * ns,
      [](ForwardFilter& f) { f.velocity_supports(nbs_flag(0), Vec3(2.5, 0.0, 0.0), ErrorModel{}); }, "nbs");
  VelocityMean v;
  v.mean_um_s[0] = 1.0, v.lag_s = 0.05, v.sigma_um_s = 0.0;
  check(
      observe::velocity_mean_row(0.05), 1.0, zs * zs, [&](ForwardFilter& f) { f.velocity_mean(v, ErrorModel{}); },
      "velocity mean");
  const double fs = m.psd_floor_um;
  check(
      observe::cupt_row(0.0), 0.5, 0.04 + fs * fs,
      [](ForwardFilter& f) { (void)f.position_fix(0, 10.5, 10.0, 0.2, ErrorModel{}, 120.0); },
      "cupt, the scale no state");
  check(
      observe::cupt_row(120.0), 0.5, 0.04 + fs * fs,
      [&](ForwardFilter& f) { (void)f.position_fix(0, 10.5, 10.0, 0.2, m, 120.0, 50.0); }, "cupt, the scale a state");
  ErrorModel timed = m;
  timed.timing_state_us = {2.0, 0.0, 0.0};
  check(
      observe::cupt_row(120.0, 50.0), 0.5, 0.04 + fs * fs,
      [&](ForwardFilter& f) { (void)f.position_fix(0, 10.5, 10.0, 0.2, timed, 120.0, 50.0); },
      "cupt, the scale and the timing states");
}

// The continuous error model of error_model.hpp: ė = A e + w, w into δv and δb.
Mat3 continuous_a() {
  Mat3 a = Mat3::Zero();
  a(0, 1) = 1.0, a(1, 2) = 1.0;
  return a;
}

// Its flow over h (RK4 in small steps).
Vec3 flow(const Vec3& e0, double h_s) {
  const Mat3 a = continuous_a();
  Vec3 e = e0;
  const int n = 100;
  const double dt = h_s / n;
  for (int i = 0; i < n; ++i) {
    const Vec3 k1 = a * e, k2 = a * (e + 0.5 * dt * k1), k3 = a * (e + 0.5 * dt * k2), k4 = a * (e + dt * k3);
    e += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return e;
}

TEST(FusionJacobian, TheTransitionIsTheJacobianOfTheContinuousFlow) {
  const ErrorModel m;
  for (double h_s : {1e-4, 0.01, 0.7}) {
    const Discrete d = discretise(m, h_s);
    const Vec3 e(0.4, -1.3, 2.2);
    Mat3 numeric;
    for (int j = 0; j < 3; ++j) {
      Vec3 ep = e, em = e;
      ep[j] += 1e-3, em[j] -= 1e-3;
      numeric.col(j) = (flow(ep, h_s) - flow(em, h_s)) / 2e-3;
    }
    EXPECT_LT((d.F.topLeftCorner<3, 3>() - numeric).cwiseAbs().maxCoeff(), 1e-9) << "h = " << h_s;
  }
}

TEST(FusionJacobian, TransitionAndNoiseEqualVanLoansExponentialOfTheContinuousModel) {
  // exp([−A  G Qc Gᵀ; 0  Aᵀ]·h) = [· F⁻¹Q; 0 Fᵀ] (Van Loan 1978).
  ErrorModel m;
  m.accel_noise_um_s2_rthz = 5.55, m.bias_walk_um_s2_rts = 2.0;
  Mat3 qc = Mat3::Zero();
  qc(1, 1) = m.accel_noise_um_s2_rthz * m.accel_noise_um_s2_rthz;
  qc(2, 2) = m.bias_walk_um_s2_rts * m.bias_walk_um_s2_rts;
  for (double h_s : {1e-4, 0.01, 0.7}) {
    Eigen::Matrix<double, 6, 6> vl = Eigen::Matrix<double, 6, 6>::Zero();
    vl.topLeftCorner<3, 3>() = -continuous_a();
    vl.topRightCorner<3, 3>() = qc;
    vl.bottomRightCorner<3, 3>() = continuous_a().transpose();
    const Eigen::Matrix<double, 6, 6> ex = (vl * h_s).exp();
    const Mat3 f = ex.bottomRightCorner<3, 3>().transpose();
    const Mat3 q = f * ex.topRightCorner<3, 3>();
    const Discrete d = discretise(m, h_s);
    EXPECT_LT((d.F.topLeftCorner<3, 3>() - f).cwiseAbs().maxCoeff(), 1e-12) << "h = " << h_s;
    EXPECT_LT((d.Q.topLeftCorner<3, 3>() - q).cwiseAbs().maxCoeff(), 1e-9 * q.cwiseAbs().maxCoeff()) << "h = " << h_s;
  }
}

}  // namespace
}  // namespace eical::dsp::fusion
