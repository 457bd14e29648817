#include "sim/scenario.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"
#include "sim/gcode/generate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace eical::sim {

double CaseTemperature::at(double t_s) const {
  return rise_c == 0.0 ? t0_c : t0_c + rise_c * (1.0 - std::exp(-t_s / tau_s));
}

bool Resonance::on() const {
  for (const auto& m : modes)
    if (m.gain != 0.0) return true;
  return false;
}

bool CommonVibration::on() const {
  return !tones.empty() || broadband_rms_mg.squaredNorm() > 0.0 || mode.gain.squaredNorm() > 0.0;
}

namespace {

// The common part of the built-in scenarios: data-sheet sensors that are also the truth,
// an ideal reference instrument on all axes.
Scenario base_scenario(dsp::ProgramKind kind, std::uint64_t seed, std::string description) {
  Scenario sc;
  sc.name = dsp::program_kind_name(kind);
  sc.seed = seed;
  sc.description = std::move(description);
  sc.meta.program.kind = kind;
  sc.meta.id = "sim-" + sc.name + "-s" + std::to_string(seed);
  sc.meta.reference = dsp::Reference{"ideal", {"x", "y", "z"}};
  for (int s = 0; s < 2; ++s) sc.truth[s].spec = sc.meta.sensors[s];
  return sc;
}

// Single-axis programs on x with a 0.5 s dwell (step and positioning).
Scenario axis_scenario(dsp::ProgramKind kind, std::vector<double> targets_mm, double feed_mm_min, int runs,
                       std::uint64_t seed, std::string description) {
  Scenario sc = base_scenario(kind, seed, std::move(description));
  auto& p = sc.meta.program;
  p.axis = "x";
  p.targets_mm = std::move(targets_mm);
  p.feed_mm_min = feed_mm_min;
  p.runs = runs;
  p.dwell_s = 0.5;
  return sc;
}

}  // namespace

Scenario circle_scenario(double radius_mm, double feed_mm_min, int repeats, const std::string& direction,
                         std::uint64_t seed) {
  Scenario sc = base_scenario(dsp::ProgramKind::circle, seed,
                              "R" + std::to_string(radius_mm) + " circle F" + std::to_string(feed_mm_min) + " x" +
                                  std::to_string(repeats) + " " + direction + ", ideal machine, data-sheet sensors");
  auto& p = sc.meta.program;
  p.plane = "xy";
  p.radius_mm = radius_mm;
  p.feed_mm_min = feed_mm_min;
  p.repeats = repeats;
  p.direction = direction;
  sc.meta.id = "sim-circle-r" + std::to_string(static_cast<int>(radius_mm)) + "-f" +
               std::to_string(static_cast<int>(feed_mm_min)) + "-s" + std::to_string(seed);
  sc.truth[1].temperature.t0_c = 20.5;
  return sc;
}

Scenario step_scenario(double from_mm, double to_mm, double feed_mm_min, int runs, std::uint64_t seed) {
  return axis_scenario(dsp::ProgramKind::step, {from_mm, to_mm}, feed_mm_min, runs, seed,
                       "x step " + std::to_string(from_mm) + " -> " + std::to_string(to_mm) + " mm, ideal machine");
}

Scenario positioning_scenario(const std::vector<double>& targets_mm, int runs, double feed_mm_min, std::uint64_t seed) {
  return axis_scenario(dsp::ProgramKind::positioning, targets_mm, feed_mm_min, runs, seed,
                       "ISO 230-2 linear cycle on x, ideal machine");
}

Scenario rectangle_scenario(double size_a_mm, double size_b_mm, double feed_mm_min, const std::string& plane,
                            int repeats, std::uint64_t seed) {
  Scenario sc = base_scenario(
      dsp::ProgramKind::rectangle, seed,
      "rectangle " + std::to_string(size_a_mm) + " x " + std::to_string(size_b_mm) + " mm, ideal machine");
  auto& p = sc.meta.program;
  p.plane = plane;
  p.corner_mm[0] = p.corner_mm[1] = 0.0;
  p.size_mm[0] = size_a_mm, p.size_mm[1] = size_b_mm;
  p.feed_mm_min = feed_mm_min;
  p.repeats = repeats;
  p.dwell_s = 0.3;
  return sc;
}

Scenario gcode_scenario(const std::string& gcode, dsp::ProgramKind kind, std::uint64_t seed) {
  Scenario sc = base_scenario(kind, seed, "G-code program, ideal machine");
  sc.meta.program.gcode = gcode;
  return sc;
}

std::vector<dsp::PsdSpec> psd_config_b(double radius_mm) { return psd_ring(radius_mm, 2); }

namespace {

// The circle's path at (x, y) is (−y, x): it runs along x where |y| > |x| (at 45°, the ties
// alternate by quadrant).
bool path_along_x(double x, double y) { return std::abs(y) != std::abs(x) ? std::abs(y) > std::abs(x) : x * y < 0.0; }

}  // namespace

std::optional<StripFacing> ring_facing(const std::vector<dsp::PsdSpec>& psd) {
  std::optional<StripFacing> facing;
  for (const auto& s : psd) {
    const double x = s.center_mm[0], y = s.center_mm[1];
    if (std::abs(std::abs(x) - std::abs(y)) < 1e-6) continue;  // at 45°: either
    const StripFacing f =
        path_along_x(x, y) == (s.measures == "x") ? StripFacing::along_path : StripFacing::across_path;
    if (facing && *facing != f) return std::nullopt;
    facing = f;
  }
  return facing;
}

std::vector<dsp::PsdSpec> psd_ring(double radius_mm, int count, StripFacing facing) {
  if (count < 1 || count > dsp::kMaxPsd)
    throw dsp::InputError("psd: " + std::to_string(count) + " strips about a circle, 1 to " +
                          std::to_string(dsp::kMaxPsd) + " possible");
  auto nm = [](double mm) { return std::round(mm * 1e6) / 1e6; };  // cos(90°) is 6e-17, not 0
  const int slots = std::max(count, 4);                            // 2 is B: a quarter apart, not opposite
  std::vector<dsp::PsdSpec> out;
  for (int k = 0; k < count; ++k) {
    const double theta = (-0.5 + 2.0 * k / slots) * std::numbers::pi;
    const double x = nm(radius_mm * std::cos(theta)), y = nm(radius_mm * std::sin(theta));
    dsp::PsdSpec strip;
    strip.measures = path_along_x(x, y) == (facing == StripFacing::along_path) ? "x" : "y";
    strip.center_mm[0] = x, strip.center_mm[1] = y;
    out.push_back(strip);
  }
  return out;
}

Scenario identify_scenario(const std::vector<dsp::PsdSpec>& psd, const std::vector<std::string>& axes,
                           std::uint64_t seed) {
  gcode::IdentifyPlan plan;
  plan.psd = psd;
  plan.axes = axes;
  return identify_scenario(plan, seed);
}

Scenario identify_scenario(const gcode::IdentifyPlan& plan, std::uint64_t seed) {
  Scenario sc =
      base_scenario(dsp::ProgramKind::identify, seed, "on-site identification across the PSD strips, ideal machine");
  sc.meta.program.gcode = gcode::identify_program(plan);
  sc.meta.psd = plan.psd;
  return sc;
}

}  // namespace eical::sim
