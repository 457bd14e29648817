#pragma once
#include "dsp/core/flag.hpp"
#include "dsp/core/sample_rate.hpp"
// Ballbar-class diagnostics of a circular test (ISO 230-4 context), from the 2-D relative
// path that eical measures. A ballbar sees only the radius; eical sees both axes, so the
// machine errors are fitted per axis against the commanded path:
//
//   e_a(t) = P_a,pass(t) + k_a·(a_cmd − c_a) − [a = x only] α·(y_cmd − c_y) − τ_a·v_a
//            − (b_a/2)·sgn(v_a) + (l_a/2)·sgn(v_b) + C_a·sin(2π a_cmd/p) + S_a·cos(2π a_cmd/p)
//            + w_b·((b_cmd − c_b)/R)²
//
// with a, b the two axes of the plane, e = measured − commanded, P a quadratic in time per
// pass (integration start offset and the slow drift that double integration leaves), k
// the scale error, α the squareness, τ the servo lag, b the backlash (lost motion), l the
// lateral play, C/S the cyclic (pitch p) error and w the bow of axis b's travel seen on
// axis a (straightness of axis b). One direction alone cannot separate τ_x from α (both
// follow sin θ); the fit then assumes equal lags and says so. Linear least squares
// over every pass (both directions) at once, spikes excluded in a second pass; reversal
// spikes are then measured per axis on the residual after each reversal, so that one
// axis' spikes are not hidden in the other's signal (thesis (8-8) fits a reference sine
// per axis for the same reason). Conventions follow ballbar practice (results.md):
// squareness positive when the angle between +X and +Y exceeds 90°; scale mismatch =
// X scale − Y scale; servo mismatch positive when X lags Y.
#include <Eigen/Core>

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace eical::dsp::eval {

// One direction of the circular test: steady revolutions only (no ramp-in/out).
struct CirclePass {
  int direction = +1;  // +1 counter-clockwise, −1 clockwise (seen from +normal)
  double fs_hz = kDefaultFs_hz;
  std::vector<Eigen::Vector2d> cmd_mm;   // commanded relative position, plane axes (u, v)
  std::vector<Eigen::Vector2d> meas_mm;  // measured relative position, same samples
};

struct DiagnosticsOptions {
  Eigen::Vector2d centre_mm = Eigen::Vector2d::Zero();
  double radius_mm = 10.0;
  // Ball-screw pitch for the cyclic error; empty = search 1..25 mm and keep the best.
  std::optional<double> cyclic_pitch_mm;
  double spike_window_s = 0.06;  // residual window after each reversal searched for spikes
  // Programmed feed; at or below the creep feed the fast residual is friction-driven
  // stick-slip, above it vibration. One feed cannot tell a vibration along an axis from
  // jerks of that axis (both are fast residuals on it); a second test at another feed can.
  double feed_mm_min = 0.0;
  double creep_feed_mm_min = 200.0;
};

struct CircleDiagnostics {
  static constexpr double kNotEvaluated = std::numeric_limits<double>::quiet_NaN();
  double backlash_x_um = 0, backlash_y_um = 0;
  // NaN: not evaluated (no reversal of that axis; the other regime's fast residual), never
  // a 0 that reads as a measured size.
  double reversal_spike_x_um = kNotEvaluated, reversal_spike_y_um = kNotEvaluated;  // positive: the axis lags
  double lateral_play_x_um = 0, lateral_play_y_um = 0;
  double cyclic_error_x_um = 0, cyclic_error_y_um = 0;  // amplitude
  double cyclic_pitch_mm = 0;
  double servo_mismatch_ms = 0;
  double squareness_urad = 0;
  double scale_mismatch_ppm = 0;
  double straightness_x_um = 0, straightness_y_um = 0;  // bow of the axis' path at mid-travel vs its ends
  // Creep feed only: peak-to-peak lag per axis, 2√3 × the fast residual RMS (sawtooth/triangle).
  double stick_slip_um = kNotEvaluated;
  double vibration_um = kNotEvaluated;  // above the creep feed: radial residual RMS above the model (fast components)
  double lag_x_ms = 0, lag_y_ms = 0;    // each axis' lag behind the set-point (common servo lag)
  double residual_rms_um = 0;           // what the model leaves
  bool servo_and_squareness_separated = false;  // needs both directions
  std::vector<std::string> notes;
};

// Why each diagnostic the fit left out is null, as result flags (figure_null on
// "diagnostics.<key>"): servo mismatch from one direction, stick-slip above the creep feed,
// vibration at it, a reversal spike of an axis that never reversed.
std::vector<Flag> null_reasons(const CircleDiagnostics& d, const DiagnosticsOptions& options);

// Throws InputError when the passes are empty, mismatched or do not go round.
CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& options);

// The passes' samples, read as often as the fit needs (three times): from stored passes,
// or from a spill of a measurement too long to hold (dsp/stream).
class PassReplay {
 public:
  struct Pass {
    int direction = +1;
    double fs_hz = kDefaultFs_hz;
    std::size_t samples = 0;
  };
  virtual ~PassReplay() = default;
  [[nodiscard]] virtual const std::vector<Pass>& passes() const = 0;
  // Every sample of every pass, pass by pass, in order.
  virtual void replay(const std::function<void(std::size_t pass, const Eigen::Vector2d& cmd_mm,
                                               const Eigen::Vector2d& meas_mm)>& sample) = 0;
};

// The same fit over replayed passes; memory independent of their length. (The least
// squares are solved from their normal equations, accumulated block by block, with the
// columns scaled as before.)
CircleDiagnostics diagnose_circle(PassReplay& replay, const DiagnosticsOptions& opt);

// What the fit takes from the set-point alone: every sample's velocity, reversal windows
// and model columns but the target and the play operator's backlash, with round one's
// normal equations of those columns. Made once, it serves every evaluation of a path on
// the same set-point, which then reads the measured path only: the uncertainty's draws
// evaluate some 200 paths on one set-point (dsp/analysis/setpoint_cache.hpp). About
// 100 B + 16 B per pitch and axis a sample, so for a path at the draws' rate (a few ten
// thousand samples), not a long run's full rate. Throws as diagnose_circle() does.
class CircleDesign;
std::shared_ptr<const CircleDesign> circle_design(const std::vector<CirclePass>& passes,
                                                  const DiagnosticsOptions& options);
// diagnose_circle(passes, opt) with the set-point's share from `design`, made of the same
// set-point and options (InputError when its passes differ).
CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& opt,
                                  const CircleDesign& design);

}  // namespace eical::dsp::eval
