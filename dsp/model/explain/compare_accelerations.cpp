// Stage: the measured acceleration against the set-point's, below the structure's modes.
// A wrong mounting (sign flip, swapped axes, a mirror) shows here on any run; on a run that
// nothing holds (no rest, no position support) this is where its sensors are judged: scale
// and mounting angle per moving axis, the lag and the bias by regression — never a double
// integral over the run called a position error (run-format.md, "No standstill").
#include "dsp/core/float_limits.hpp"
#include "dsp/model/acceleration_comparison.hpp"
#include "dsp/model/explain/stages.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {
namespace {

// The band compared: below the slowest mode found (its response is then a few per cent of
// the commanded acceleration), at most 20 Hz, at least 2 Hz.
double band_hz(const ExplainState& st) {
  double fc = 20.0;
  for (const auto& m : st.modes) fc = std::min(fc, m.frequency_hz / 2.5);
  return std::max(fc, 2.0);
}

const char* sensor_name(int s) { return s == 0 ? "table" : "head"; }

std::string comparison_text(const AccelerationComparison& c) {
  return fmt("below %.0f Hz the measured acceleration follows the commanded one to %.1f %% of its variance; lag %.2f "
             "+- %.2f ms",
             c.cutoff_hz, 100.0 * c.explained_fraction, c.lag_s * 1e3, c.lag_sigma_s * 1e3) +
         fmt("; bias by regression (%.3g, %.3g, %.3g) mg", c.bias_mm_s2[0] / 9.80665, c.bias_mm_s2[1] / 9.80665,
             c.bias_mm_s2[2] / 9.80665);
}

}  // namespace

std::optional<MountingFit> wrong_mounting(const ExplainState& st) {
  if (st.rr.n < 200) return std::nullopt;
  return gross_mounting(st.rr, compare_accelerations(st.rr, 20.0));
}

ExplainedEffect mounting_effect(const MountingFit& m) {
  ExplainedEffect x = effect_of(Effect::sensor_misalignment);
  // Not an angle within a tolerance but a wrong axes map: its own unit, no angle's bound.
  x.unit = "axes map", x.magnitude = 1.0, x.tolerance = 0.5;
  x.channel = "acceleration";
  x.significant = true;
  x.importance_um = kInf;  // first: every other finding is explained with this mounting
  x.resembles = "the commanded acceleration on another measured axis or with the other sign";
  x.evidence = std::string("the ") + sensor_name(m.sensor) + " sensor is not mounted as run.toml says: " + m.evidence +
               "; the mounting that fits is the axes map " + m.axes_map + " applied to run.toml's to_machine" +
               fmt(", to_machine = [[%g, %g, %g], ", m.to_machine(0, 0), m.to_machine(0, 1), m.to_machine(0, 2)) +
               fmt("[%g, %g, %g], ", m.to_machine(1, 0), m.to_machine(1, 1), m.to_machine(1, 2)) +
               fmt("[%g, %g, %g]]; the effects below are explained with it", m.to_machine(2, 0), m.to_machine(2, 1),
                   m.to_machine(2, 2));
  x.params["sensor"] = m.sensor;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) x.params["to_machine_" + std::to_string(r) + std::to_string(c)] = m.to_machine(r, c);
  return x;
}

void compare_accelerations(ExplainState& st) {
  if (st.integration_supported) return;
  const AccelerationComparison c = compare_accelerations(st.rr, band_hz(st));
  if (!c.valid) {
    ExplainedEffect note = effect_of(Effect::sensor_scale);
    note.channel = "acceleration";
    note.evidence =
        "nothing holds the double integral (no rest, no position support) and the accelerations cannot be compared: " +
        c.why;
    st.merge(std::move(note));
    return;
  }
  ExplainedEffect scale = effect_of(Effect::sensor_scale), angle = effect_of(Effect::sensor_misalignment);
  scale.channel = angle.channel = "acceleration";
  double scale_sure = 0.0, angle_sure = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!c.input[static_cast<std::size_t>(i)]) continue;
    const double g = c.gain(i, i), sg = c.gain_sigma(i, i);
    const double s_ppm = (g - 1.0) * 1e6, ss_ppm = sg * 1e6;
    scale.params["scale_" + axis_letter(i) + "_ppm"] = s_ppm,
                                             scale.params["sigma_scale_" + axis_letter(i) + "_ppm"] = ss_ppm;
    if (std::abs(s_ppm) > std::abs(scale.magnitude)) scale.magnitude = s_ppm, scale.sigma = ss_ppm;
    scale_sure = std::max(scale_sure, std::abs(s_ppm) - 2.0 * ss_ppm);
    // The commanded axis seen on the other measured axes: the mounting's angle (with one
    // moving axis per sensor, mounting and cross coupling are one effect here).
    double off = 0.0, off_var = 0.0;
    for (int j = 0; j < 3; ++j)
      if (j != i) off += c.gain(j, i) * c.gain(j, i), off_var += c.gain_sigma(j, i) * c.gain_sigma(j, i);
    const double a_mrad = std::atan2(std::sqrt(off), std::abs(g)) * 1e3,
                 sa_mrad = std::sqrt(off_var) / std::max(std::abs(g), 1e-9) * 1e3;
    angle.params["angle_" + axis_letter(i) + "_mrad"] = a_mrad,
                                             angle.params["sigma_angle_" + axis_letter(i) + "_mrad"] = sa_mrad;
    if (a_mrad > angle.magnitude) angle.magnitude = a_mrad, angle.sigma = sa_mrad;
    angle_sure = std::max(angle_sure, a_mrad - 2.0 * sa_mrad);
  }
  scale.significant = scale_sure > scale.tolerance;
  angle.significant = angle_sure > angle.tolerance;
  scale.importance_um = scale.significant ? 1.0 : 0.0, angle.importance_um = angle.significant ? 1.0 : 0.0;
  scale.resembles =
      "the commanded acceleration along the axis (or the axis' steps per mm: against the set-point alone they are one)";
  angle.resembles = "the commanded acceleration on the other measured axes";
  const std::string text = comparison_text(c);
  scale.evidence =
      "nothing holds the double integral, so the acceleration is compared: " + text +
      fmt("; gain on the moving axes off by up to %.0f ppm (%.0f at 2 sigma) against a tolerance of %.0f ppm",
          scale.magnitude, scale_sure, scale.tolerance);
  angle.evidence = "nothing holds the double integral, so the acceleration is compared: " + text +
                   fmt("; the commanded axis seen on the others at up to %.2f mrad (%.2f at 2 sigma) against a "
                       "tolerance of %.1f mrad",
                       angle.magnitude, angle_sure, angle.tolerance);
  scale.params["lag_ms"] = angle.params["lag_ms"] = c.lag_s * 1e3;
  scale.params["explained_fraction"] = c.explained_fraction;
  for (int j = 0; j < 3; ++j) scale.params["bias_" + axis_letter(j) + "_mg"] = c.bias_mm_s2[j] / 9.80665;
  st.merge(std::move(scale));
  st.merge(std::move(angle));
}

}  // namespace eical::dsp::model::stage
