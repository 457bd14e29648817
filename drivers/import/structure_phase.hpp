#pragma once
// The structure's phase, taken out before the time offset is estimated (issue 34).
// A printer's head rings at its modes: there the measured acceleration is several times the
// commanded one and its phase turns by up to 180°. A cross-correlation with the commanded
// acceleration follows that phase as well as the clocks' offset: on 16 simulated Klipper
// sweeps (klipper-like regime) it came out 21–363 µs late, each by 1.2–2.6 u.
//
// The magnitude of the response needs no alignment: |H(f)|² = Σ_a |Y_a(f)|² / Σ_c |R_c(f)|²
// (a delay and the mounting's rotation leave both sums unchanged). A structure driven at
// one point through its drive — rigid body plus modes, or a mass on a belt — is minimum
// phase (its zeros lie in the left half plane), so its phase follows from that magnitude
// (Bode's gain–phase relation, by the folded real cepstrum). The measurement divided by
// that response is the commanded acceleration through a constant gain, delayed by the
// offset alone.
//
// What it leaves: a magnitude that is not the structure's. A zero-phase droop of the
// acquisition (4 % at 300 Hz on one simulated chip) is read as a low-pass and moves the
// offset by some tens of µs, which neither the jackknife nor the extension bracket sees.
#include <complex>
#include <cstddef>
#include <vector>

namespace eical::drivers {

// |H| as measured: ln|H| on the excited bins 0 .. L/2 (0 elsewhere), computed once and
// extended beyond them by each guess of `Beyond`.
struct ResponseMagnitude {
  double bin_hz = 0.0;
  std::vector<double> log_h;
  std::vector<bool> excited;
  double level = 0.0;  // median |H| over the excited bins; 0 when none is excited
};

struct StructureResponse {
  double bin_hz = 0.0;
  std::vector<std::complex<double>> inverse;  // per bin 0 .. L/2: level / H_min(f); empty: none
  double peak_over_level = 0.0;               // max |H| / level: 1 for a rigid structure
};

// A bin is excited where the smoothed reference power exceeds this fraction of its peak;
// beyond the excited bins |H| is held at the nearest excited value.
inline constexpr double kExcitedFraction = 1e-4;
// A bin counts where its measured power exceeds the noise by this factor (|H|² from the
// power above the noise: the noise would raise |H| at the band's edges, and the phase
// derived from that edge would shift the offset).
inline constexpr double kMinSignalToNoise = 20.0;
// |H|² is smoothed over ± this: a chirp's spectrum is ragged from bin to bin; a printer's
// lightest damped mode (ζ 0.01 at 30 Hz) is 0.6 Hz wide. ±0.1 and ±0.5 Hz moved the
// offsets of the 28 regime runs by up to 50 µs either way, ±0.25 Hz was between them.
inline constexpr double kSmoothingHalfWidth_hz = 0.25;

// Where the reference does not excite the structure its magnitude is unknown, and the
// phase in the band depends on it: a step of ln|H| by Δ at f_e turns the phase below f_e
// like a delay of Δ / (π² f_e). Two guesses bracket it: each edge's value held outward (a
// response that stays as it ends), or the band's median level.
enum class Beyond { hold_edges, level };

// y: the measured axes and r: the reference columns, both on the same grid (fs_hz), zero
// padded to L (a power of two) inside.
ResponseMagnitude response_magnitude(const std::vector<std::vector<double>>& y,
                                     const std::vector<std::vector<double>>& r, double fs_hz, std::size_t L);

// The inverse of the minimum-phase response with that magnitude, extended as `beyond` says.
StructureResponse minimum_phase_inverse(const ResponseMagnitude& m, Beyond beyond);

// x filtered by w (w[k] at k · bin_hz for k ≥ 0, conjugate at −f; 0 beyond), x's samples
// dt_s apart.
void apply_response(std::vector<double>& x, double dt_s, const std::vector<std::complex<double>>& w, double bin_hz);

}  // namespace eical::drivers
