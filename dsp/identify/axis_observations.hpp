#pragma once
// The observations of one machine axis' augmented filter (augmented_filter.hpp) in the
// sensor identification: which parameters the axis' filter carries, and for every kind of
// observation its measurement model — what the observed z predicts from the filter's state
// [δx µm, δv µm/s, δb µm/s², θ …] — and the row h that linearises it (z = h·state). The
// models are linear, so h is their gradient; tests/dsp/identification_jacobian_test.cpp
// checks each row against central differences of its model.
#include "dsp/core/axes.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/core/sensor_model_covariance.hpp"

#include <Eigen/Core>

#include <cmath>
#include <vector>

namespace eical::dsp::identify {

inline constexpr double kPriorError = 0.02;     // E_ij: scale and cross terms, 2 %
inline constexpr double kPriorDampingMs = 0.2;  // Δ(2ζ/ω0), ms (data sheet 0.225 ms)
inline constexpr double kPriorOffsetUm = 50.0;  // rest offsets, backlash, PSD mounting
// A strip's nonlinearity: uniform within the data sheet's bound.
inline double prior_strip_nonlinearity() { return DatasheetTolerance{}.psd_nonlinearity / std::sqrt(3.0); }

// Parameter indices of one axis' filter (−1: not fitted).
struct Layout {
  int e[3] = {-1, -1, -1};  // E_ij, j = the axis whose acceleration it scales
  int damping = -1, x0 = -1, backlash = -1;
  std::vector<int> strip;     // per PSD strip of the run (−1 when it measures another axis)
  std::vector<int> strip_nl;  // its nonlinearity (−1: not fitted)
  int count = 0;
};

// The parameters of axis i and their prior σ (in the order of their indices): E_ij for
// every moved axis j, Δ(2ζ/ω0) when i moved; against the set-point the rest offset, the
// backlash (when i moved) and the mounting offset of each strip measuring i and, where i
// moved, its nonlinearity; against a reference its zero only.
struct AxisPrior {
  Layout layout;
  std::vector<double> sigma;
};

inline AxisPrior axis_prior(int i, const bool moved[3], const std::vector<PsdSpec>& psd, bool against_reference) {
  AxisPrior p;
  Layout& L = p.layout;
  const auto add = [&p](double prior) {  // the index of a new parameter
    p.sigma.push_back(prior);
    return static_cast<int>(p.sigma.size()) - 1;
  };
  for (int j = 0; j < 3; ++j)
    if (moved[j]) L.e[j] = add(kPriorError);
  if (moved[i]) L.damping = add(kPriorDampingMs);
  if (!against_reference) {
    L.x0 = add(kPriorOffsetUm);
    if (moved[i]) L.backlash = add(kPriorOffsetUm);
    L.strip.assign(psd.size(), -1);
    L.strip_nl.assign(psd.size(), -1);
    for (std::size_t s = 0; s < psd.size(); ++s)
      if (axis_index(psd[s].measures) == i) {
        L.strip[s] = add(kPriorOffsetUm);
        // A strip's nonlinearity: the least-squares slope of nl·u·(2u/L)² against u over a
        // swing across the strip is 0.6·nl, a scale error of the axis (up to 60 ppm at the
        // data sheet's bound, 35 ppm rms). Fitted beside the scale, the rest of its shape
        // (u³ − 0.6·(L/2)²·u) tells the two apart.
        if (moved[i]) L.strip_nl[s] = add(prior_strip_nonlinearity());
      }
  } else {
    L.x0 = add(kPriorOffsetUm);  // the reference's zero
  }
  L.count = static_cast<int>(p.sigma.size());
  return p;
}

// The observations. (Header only: the models and rows are a few lines each, and the
// tests call them.)
namespace observe {

// A parameter of the state (0 when the layout does not fit it).
inline double param(const Eigen::VectorXd& state, int index) { return index >= 0 ? state[3 + index] : 0.0; }

// A standstill's middle: integrated − set-point = δx + x0 + b·direction/2, direction that
// of the axis' last move (±1, 0 before the first).
inline double rest(const Layout& L, const Eigen::VectorXd& state, double direction) {
  return state[0] + param(state, L.x0) + param(state, L.backlash) * direction / 2.0;
}
inline void rest_row(const Layout& L, double direction, Eigen::RowVectorXd& h) {
  h.setZero();
  h[0] = 1.0, h[3 + L.x0] = 1.0;
  if (L.backlash >= 0) h[3 + L.backlash] = direction / 2.0;
}

// The integration starts at the set-point: integrated − set-point = δx + x0 = 0 at k = 0
// (the backlash' direction is unknown before the first move).
inline double start(const Layout& L, const Eigen::VectorXd& state) { return rest(L, state, 0.0); }
inline void start_row(const Layout& L, Eigen::RowVectorXd& h) {
  h.setZero();
  h[0] = 1.0, h[3 + L.x0] = 1.0;
  if (L.backlash >= 0) h[3 + L.backlash] = 0.0;  // direction unknown before the first move
}

// A standstill: the integrated velocity = δv (ZUPT).
inline double zupt(const Eigen::VectorXd& state) { return state[1]; }
inline void zupt_row(Eigen::RowVectorXd& h) {
  h.setZero();
  h[1] = 1.0;
}

// A ringing standstill's mean velocity over a window whose mean time lies lag_s before the
// sample: δv − lag·δb.
inline double velocity_mean(const Eigen::VectorXd& state, double lag_s) { return state[1] - lag_s * state[2]; }
inline void velocity_mean_row(double lag_s, Eigen::RowVectorXd& h) {
  h.setZero();
  h[1] = 1.0, h[2] = -lag_s;
}

// A lit PSD sample of `strip`, `cubic_um` its supports::psd_nonlinearity_shape_um: integrated − reading =
// δx + Δ(2ζ/ω0)·v − o_strip − nl_strip·cubic (Δ(2ζ/ω0) in ms, v in µm/s).
inline double psd(const Layout& L, const Eigen::VectorXd& state, double v_um_s, int strip, double cubic_um) {
  const auto s = static_cast<std::size_t>(strip);
  const double nl = s < L.strip_nl.size() ? param(state, L.strip_nl[s]) : 0.0;
  return state[0] + param(state, L.damping) * v_um_s * 1e-3 - param(state, L.strip[s]) - nl * cubic_um;
}
inline void psd_row(const Layout& L, double v_um_s, int strip, double cubic_um, Eigen::RowVectorXd& h) {
  const auto s = static_cast<std::size_t>(strip);
  h.setZero();
  h[0] = 1.0;
  if (L.damping >= 0) h[3 + L.damping] = v_um_s * 1e-3;  // ms × µm/s
  h[3 + L.strip[s]] = -1.0;
  if (s < L.strip_nl.size() && L.strip_nl[s] >= 0) h[3 + L.strip_nl[s]] = -cubic_um;
}

// A reference instrument's reading: integrated − reference = δx + x0 + Δ(2ζ/ω0)·v (x0: the
// reference's zero).
inline double reference(const Layout& L, const Eigen::VectorXd& state, double v_um_s) {
  return state[0] + param(state, L.x0) + param(state, L.damping) * v_um_s * 1e-3;
}
inline void reference_row(const Layout& L, double v_um_s, Eigen::RowVectorXd& h) {
  h.setZero();
  h[0] = 1.0, h[3 + L.x0] = 1.0;
  if (L.damping >= 0) h[3 + L.damping] = v_um_s * 1e-3;
}

}  // namespace observe
}  // namespace eical::dsp::identify
