#pragma once
// Frequency response of a measured signal against a commanded one (H1 estimator, Welch:
// Hann segments, half overlapping): H = S_yu / S_uu, with the coherence
// γ² = |S_yu|² / (S_uu S_yy) that says how much of y the input explains at each frequency.
// Any excitation will do — a sweep, the transients of a circle or a step; where the input
// has no power the coherence says so.
#include <Eigen/Core>

#include <complex>
#include <cstddef>
#include <vector>

namespace eical::dsp::model {

struct FrequencyResponse {
  double df_hz = 0.0;
  int averages = 0;                     // segments averaged
  std::vector<double> f_hz;             // bin centres, from 0 to fs/2
  std::vector<std::complex<double>> h;  // y per u
  std::vector<double> coherence;        // γ², 0..1
  std::vector<double> s_uu;             // input power (arbitrary scale)
};

// `segment` samples per segment (rounded down to a power of two, at least 64); empty when
// the signals are shorter than one segment.
FrequencyResponse frequency_response(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double fs_hz,
                                     std::size_t segment);

// The segment for a run of n samples: df about `df_hz`, at least `min_averages` segments.
std::size_t segment_for(std::size_t n, double fs_hz, double df_hz, int min_averages);

}  // namespace eical::dsp::model
