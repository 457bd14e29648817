#pragma once
// The fusion's support observations (forward_filter.hpp), each as its measurement function
// — what the observation z predicts from one axis' error state e = [δx µm, δv µm/s,
// δb µm/s², δs ppm, δτ µs] (error_model.hpp) — and the row h that linearises it (z = h·e + noise). The
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
// along the axis and at the integrated velocity vel_mm_s along it: the scale error has
// made δs·way of it (1 ppm of 1 mm is 1e-3 µm), the timing error δτ·v (1 µs at 1 mm/s is
// 1e-3 µm). way_mm, vel_mm_s = 0 where the scale, the timing is no state.
inline double cupt(const State& e, double way_mm, double vel_mm_s = 0.0) {
  return e[0] + 1e-3 * way_mm * e[kScaleState] + 1e-3 * vel_mm_s * e[kTimingState];
}
inline StateRow cupt_row(double way_mm, double vel_mm_s = 0.0) {
  StateRow h = StateRow::Unit(0);
  h[kScaleState] = 1e-3 * way_mm;
  h[kTimingState] = 1e-3 * vel_mm_s;
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
inline StateRow velocity_mean_row(double lag_s) {
  StateRow h = StateRow::Zero();
  h[1] = 1.0, h[2] = -lag_s;
  return h;
}

}  // namespace eical::dsp::fusion::observe
