#pragma once
// Structural modes between the drive and the measured point, from the frequency response of
// the measured over the commanded acceleration (frequency_response.hpp). A rigid machine
// follows its set-point: H ≈ 1 with the servo's slow phase. A mode adds, near its
// frequency, a resonant term (base excitation of a lightly damped mass):
//   H(s) = A + B·(f − f_p) + G · s² / (s² + 2ζω s + ω²)          (per response axis)
// fitted in a window about each peak, every frequency bin weighted by what its coherence
// says of its variance: var(H) = |H|² (1 − γ²) / (2 K γ²) for K averages. A mode counts
// when the fit with it is better than a smooth response by χ² at z = 5 for its parameters
// and it amplifies the commanded acceleration by at least 10 % at its peak, and what it adds
// to this run stands out of the sensors' noise: 0.1 µm RMS of relative position or 0.1 mg of
// acceleration. A structural mode is lightly damped (ζ ≤ 0.1); broader shapes are none.
// The modes are chosen as a model: forward from the response's peaks and then from what
// the modes kept leave, refitted jointly; backward until every mode explains the response
// beside the others and no two overlap in their half-power bands (one peak, one mode).
#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace eical::dsp::model {

struct StructuralMode {
  double frequency_hz = 0.0, sigma_frequency_hz = 0.0;
  double damping_ratio = 0.0, sigma_damping_ratio = 0.0;
  double gain = 0.0;                  // |G| of the strongest response axis (per unit commanded acceleration)
  double peak_amplification = 0.0;    // |G| / (2ζ) / |A|: how much the mode adds at its peak
  int input_axis = 0;                 // the commanded axis that excites it best
  std::array<double, 3> direction{};  // response per axis (|G|, normalised; sign against the input axis)
  double chi2_drop = 0.0, chi2_threshold = 0.0;
  double coherence = 0.0;            // at the peak
  double response_rms_mg = 0.0;      // what the mode adds to the measured acceleration over the run
  double displacement_rms_um = 0.0;  // and to the position (the same over ω²)
  bool significant = false;
};

struct ModeSearch {
  std::vector<StructuralMode> modes;  // strongest first
  double f_min_hz = 0.0, f_max_hz = 0.0, df_hz = 0.0;
  int averages = 0;
  // The gain of the modes found: measured − commanded acceleration beyond the drive's own
  // response (gain, lag, curvature), RMS over the run without and with them, mg.
  double residual_rms_before_mg = 0.0, residual_rms_after_mg = 0.0;
  std::string evidence;  // what was searched, or why nothing could be
};

// A mode's response to its drive u (mm/s²): m'' + 2ζω m' + ω² m = u (base excitation);
// its relative acceleration m'' (mm/s²), or its displacement m (mm) when `displacement`.
Eigen::VectorXd mode_response(const Eigen::VectorXd& u, double fs_hz, double f_hz, double zeta, bool displacement);

// `a_meas`, `a_cmd`: n × 3 (mm/s², same time base, sample rate fs_hz); `driven`: the axes the
// set-point moves (the inputs); `max_hz`: the highest frequency a mode may have here (the
// search stops at 0.4·fs in any case).
ModeSearch find_structural_modes(const Eigen::MatrixXd& a_meas, const Eigen::MatrixXd& a_cmd, double fs_hz,
                                 const std::array<bool, 3>& driven, double max_hz);

}  // namespace eical::dsp::model
