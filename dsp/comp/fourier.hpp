#pragma once
// Fourier calibration function of a rotary axis (seed 001, Depenthal):
//   F(x) = Σ A_l sin(f_l x + φ_l)                                           (2)
// from interleaved measurement series ("eingehängte Messreihen"): each series measures
// n positions Δx = 360°/n apart (a mirror polygon) from its own start angle; its summed
// division errors refer to that start, so the series are centred by their means onto the
// first one (5, 6). Centring removes every frequency f = k·n (the series' means contain
// them, 9); those are recovered from a continuous sweep over one interval Δx after the
// other terms are subtracted. Candidate frequencies come from the spectrum of the
// centred data, amplitudes and phases from least squares, and each term is kept only if
// significant (Wald test of its sine/cosine pair, F(2, ν) at level α). Uncertainty per
// GUM: U = 2·√(u_x² + u_p²) (10, 11), u_x from the fit's covariance, u_p = a/√3 from
// the axis' positioning deviation bound ±a (type B, rectangular).
#include <string>
#include <vector>

namespace eical::dsp::comp {

struct AngleSeries {
  std::string name;
  std::vector<double> angle_deg;
  std::vector<double> deviation_arcsec;
};

struct FourierOptions {
  double alpha = 0.05;                    // significance level of each term
  int max_frequency = 0;                  // highest candidate (per revolution); 0 = Nyquist of the combined grid
  double candidate_sigma = 2.0;           // spectrum lines above this many noise σ become candidates
  double positioning_bound_arcsec = 0.0;  // ±a of the axis' positioning deviation (type B)
  std::string sweep_series;               // name of the continuous sweep over one interval ("" = none)
};

struct FourierTerm {
  int frequency = 0;  // per revolution
  double amplitude_arcsec = 0.0;
  double phase_deg = 0.0;
  double u_amplitude_arcsec = 0.0;  // standard uncertainty
  double test_statistic = 0.0;      // F value of the pair
  bool significant = false;
  bool from_sweep = false;  // f = k·n, recovered from the sweep
};

struct FourierResult {
  int points_per_series = 0;  // n
  int series = 0;
  std::vector<double> series_offset_arcsec;  // S̄_m − S̄_1 removed from each series
  std::vector<FourierTerm> terms;            // significant terms (and the tested rejects, flagged)
  std::vector<int> lost_frequencies;         // k·n up to the highest candidate: removed by centring
  double residual_rms_arcsec = 0.0;
  double u_x_arcsec = 0.0, u_p_arcsec = 0.0, expanded_U_arcsec = 0.0;  // k = 2
  // F at x (deg) from the significant terms.
  [[nodiscard]] double evaluate(double angle_deg) const;
};

// Throws InputError on inconsistent series (different n, NaN, fewer than 2 series).
FourierResult fourier_calibration(const std::vector<AngleSeries>& series, const FourierOptions& options);

// Quantile of F(2, ν) for the upper tail α (closed form: (ν/2)(α^(−2/ν) − 1)).
double f2_quantile(double alpha, double nu);

}  // namespace eical::dsp::comp
