#pragma once
// The fusion's support observations (forward_filter.hpp), each as its measurement function
// — what the observation z predicts from one axis' error state e = [δx µm, δv µm/s,
// δb µm/s², δs ppm] (error_model.hpp) — and the row h that linearises it (z = h·e + noise). The
// filter updates with the rows; tests/dsp/fusion_jacobian_test.cpp checks each against
// central differences of its function.
#include "dsp/fusion/error_model.hpp"

#include <vector>

namespace eical::dsp::fusion::observe {

// ZUPT: the integrated velocity at a standstill (the machine rests: all of it is error;
// the scale's share of a zero velocity is zero).
inline double zupt(const State& e) { return e[1]; }
inline StateRow zupt_row() { return StateRow::Unit(1); }

// NBS: the integrated velocity of an axis the set-point holds.
inline double nbs(const State& e) { return e[1]; }
inline StateRow nbs_row() { return StateRow::Unit(1); }

// CUPT: the integrated position minus a PSD strip's reading, at way_mm from the start
// along the axis: the scale error has made δs·way of it (1 ppm of 1 mm is 1e-3 µm).
// way_mm = 0 where the scale is no state.
inline double cupt(const State& e, double way_mm) { return e[0] + 1e-3 * way_mm * e[kScaleState]; }
inline StateRow cupt_row(double way_mm) {
  StateRow h = StateRow::Unit(0);
  h[kScaleState] = 1e-3 * way_mm;
  return h;
}

// A ringing standstill: the mean integrated velocity over a window of samples ago_s[i]
// seconds before sample k, where the state is e — each the velocity error there by the
// continuous model run back from k (δv' = δb: δv(t_k − τ) = δv_k − τ·δb).
inline double window_mean_velocity(const State& e, const std::vector<double>& ago_s) {
  double sum = 0.0;
  for (double tau : ago_s) sum += e[1] - tau * e[2];
  return sum / static_cast<double>(ago_s.size());
}
// Its row; lag_s: from the window's mean time to sample k (the mean of ago_s).
inline StateRow velocity_mean_row(double lag_s) { return {0.0, 1.0, -lag_s, 0.0}; }

}  // namespace eical::dsp::fusion::observe
