// The identification's hand-written observation rows (dsp/identify/axis_observations.hpp)
// against central differences of the measurement models they linearise, as basalt checks
// its Jacobians, and the augmented filter's prediction against the continuous model it
// discretises. A row with a wrong index, sign or unit fails here.
#include "dsp/identify/augmented_filter.hpp"
#include "dsp/identify/axis_observations.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>
#include <string>
#include <vector>

namespace eical::dsp::identify {
namespace {

// ∂f/∂x by central differences, every component of x.
template <class F>
Eigen::RowVectorXd numeric_row(const F& f, const Eigen::VectorXd& x, double step) {
  Eigen::RowVectorXd h(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += step, xm[i] -= step;
    h[i] = (f(xp) - f(xm)) / (2.0 * step);
  }
  return h;
}

// The layouts identify_sensors builds: each axis, some axes moved or not, against the
// set-point (strips on x, y and z, two on x: a strip's index is not its axis') or against
// a reference.
struct Case {
  std::string name;
  Layout layout;
};
std::vector<Case> layouts() {
  std::vector<PsdSpec> psd(4);
  psd[0].measures = "x", psd[1].measures = "y", psd[2].measures = "x", psd[3].measures = "z";
  const bool patterns[3][3] = {{true, true, true}, {true, true, false}, {false, true, true}};
  std::vector<Case> cases;
  for (int p = 0; p < 3; ++p)
    for (int i = 0; i < 3; ++i)
      for (bool against_reference : {false, true}) {
        std::string name = "axis ";
        name += "xyz"[i];
        name += ", moved pattern " + std::to_string(p);
        name += against_reference ? ", reference" : ", set-point";
        cases.push_back({name, axis_prior(i, patterns[p], psd, against_reference).layout});
      }
  return cases;
}

// A state with every component non-zero and distinct.
Eigen::VectorXd some_state(int parameters, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  Eigen::VectorXd x(3 + parameters);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = u(rng);
  return x;
}

// |analytic − numeric| per entry; the models are linear, so only rounding separates them.
void expect_row(const Eigen::RowVectorXd& analytic, const Eigen::RowVectorXd& numeric, const std::string& what) {
  ASSERT_EQ(analytic.size(), numeric.size()) << what;
  for (Eigen::Index i = 0; i < analytic.size(); ++i)
    EXPECT_NEAR(analytic[i], numeric[i], 1e-9 * (1.0 + std::abs(numeric[i]))) << what << ", state " << i;
}

TEST(IdentificationJacobian, EveryObservationRowIsTheGradientOfItsModel) {
  std::mt19937_64 rng(7);
  for (const Case& c : layouts()) {
    const Layout& L = c.layout;
    const Eigen::VectorXd x = some_state(L.count, rng);
    Eigen::RowVectorXd h(3 + L.count);
    const double step = 1e-3;
    if (L.strip.empty()) {  // against a reference: its zero and the damping term
      for (double v_um_s : {0.0, 3500.0, -1200.0}) {
        observe::reference_row(L, v_um_s, h);
        expect_row(h, numeric_row([&](const Eigen::VectorXd& s) { return observe::reference(L, s, v_um_s); }, x, step),
                   c.name + ": reference at " + std::to_string(v_um_s) + " um/s");
      }
    } else {
      observe::start_row(L, h);
      expect_row(h, numeric_row([&](const Eigen::VectorXd& s) { return observe::start(L, s); }, x, step),
                 c.name + ": start");
      for (double dir : {-1.0, 0.0, 1.0}) {
        observe::rest_row(L, dir, h);
        expect_row(h, numeric_row([&](const Eigen::VectorXd& s) { return observe::rest(L, s, dir); }, x, step),
                   c.name + ": rest, direction " + std::to_string(dir));
      }
      for (int strip = 0; strip < static_cast<int>(L.strip.size()); ++strip) {
        if (L.strip[static_cast<std::size_t>(strip)] < 0) continue;  // a strip of another axis: not this filter's
        for (double v_um_s : {0.0, 2000.0, -6500.0})
          for (double cubic_um : {0.0, 1191.6, -4706.0}) {  // u·(2u/L)² at u 0, 3.1, −4.9 mm on 10 mm
            observe::psd_row(L, v_um_s, strip, cubic_um, h);
            expect_row(
                h,
                numeric_row([&](const Eigen::VectorXd& s) { return observe::psd(L, s, v_um_s, strip, cubic_um); }, x,
                            step),
                c.name + ": strip " + std::to_string(strip) + " at " + std::to_string(v_um_s) + " um/s, shape " +
                    std::to_string(cubic_um) + " um");
          }
      }
    }
    observe::zupt_row(h);
    expect_row(h, numeric_row([&](const Eigen::VectorXd& s) { return observe::zupt(s); }, x, step), c.name + ": zupt");
    for (double lag_s : {0.0, 0.05, 0.4}) {
      observe::velocity_mean_row(lag_s, h);
      expect_row(h, numeric_row([&](const Eigen::VectorXd& s) { return observe::velocity_mean(s, lag_s); }, x, step),
                 c.name + ": velocity mean, lag " + std::to_string(lag_s) + " s");
    }
  }
}

// The continuous model of augmented_filter.hpp, δx' = δv, δv' = δb + g·θ, δb' = 0, θ' = 0
// (g constant over the step), integrated by RK4 in small steps.
Eigen::VectorXd flow(const Eigen::VectorXd& x0, const Eigen::VectorXd& g, double h_s) {
  const auto rate = [&g](const Eigen::VectorXd& x) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(x.size());
    d[0] = x[1];
    d[1] = x[2] + g.dot(x.tail(g.size()));
    return d;
  };
  Eigen::VectorXd x = x0;
  const int n = 200;
  const double dt = h_s / n;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd k1 = rate(x), k2 = rate(x + 0.5 * dt * k1), k3 = rate(x + 0.5 * dt * k2),
                          k4 = rate(x + dt * k3);
    x += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return x;
}

TEST(IdentificationJacobian, ThePredictionIsTheFlowOfTheContinuousModel) {
  // A filter with parameters and a state whose every component is non-zero (the error
  // states through updates): its predicted state against the continuous model's flow, and
  // the flow's Jacobian by central differences against the transition the covariance
  // takes (P ← F P Fᵀ + Q: the cross-covariance of the parameters with δx, δv is F's rows).
  fusion::ErrorModel model;
  const Eigen::VectorXd prior_sigma = Eigen::Vector3d(0.02, 0.03, 50.0);
  const Eigen::VectorXd prior_mean = Eigen::Vector3d(0.01, -0.02, 4.0);
  AugmentedFilter f(model, Eigen::Vector3d(50.0, 1.0, 20.0), prior_sigma, prior_mean);
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(6);
  for (int s = 0; s < 3; ++s) {  // δx, δv and δb observed away from zero
    row.setZero();
    row[s] = 1.0;
    f.update(row, 3.0 + s, 0.1);
  }
  const Eigen::VectorXd g =
      Eigen::Vector3d(1500.0, -800.0, 0.0);  // E's gains; the third parameter acts at the position
  const double h_s = 0.01;
  const Eigen::VectorXd x0 = f.state();
  const Eigen::MatrixXd p0 = f.covariance();
  ASSERT_GT(x0.head<3>().cwiseAbs().minCoeff(), 0.1);
  f.predict(h_s, g, false);
  const Eigen::VectorXd expected = flow(x0, g, h_s);
  for (Eigen::Index i = 0; i < x0.size(); ++i)
    EXPECT_NEAR(f.state()[i], expected[i], 1e-9 * (1.0 + std::abs(expected[i]))) << "state " << i;

  // F by central differences of the flow; P's parameter columns must be F·P's (Q does not
  // reach them).
  Eigen::MatrixXd F(x0.size(), x0.size());
  for (Eigen::Index j = 0; j < x0.size(); ++j) {
    Eigen::VectorXd xp = x0, xm = x0;
    xp[j] += 1e-3, xm[j] -= 1e-3;
    F.col(j) = (flow(xp, g, h_s) - flow(xm, g, h_s)) / 2e-3;
  }
  const Eigen::MatrixXd fp = F * p0;
  for (Eigen::Index i = 0; i < 3; ++i)
    for (Eigen::Index j = 3; j < x0.size(); ++j)
      EXPECT_NEAR(f.covariance()(i, j), fp(i, j), 1e-8 * (1.0 + std::abs(fp(i, j)))) << "P(" << i << ", " << j << ")";
}

}  // namespace
}  // namespace eical::dsp::identify
