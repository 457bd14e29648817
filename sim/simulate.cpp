#include "sim/simulate.hpp"

#include "dsp/core/error.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/sensor/pt2.hpp"
#include "sim/truth.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <random>

namespace eical::sim {
namespace {

bool contains(const std::vector<std::string>& axes, int axis) {
  const char name[2] = {static_cast<char>('x' + axis), 0};
  return std::find(axes.begin(), axes.end(), name) != axes.end();
}


// The common part of the built-in scenarios: data-sheet sensors that are also the truth,
// an ideal reference instrument on all axes.
Scenario base_scenario(const std::string& kind, std::uint64_t seed, std::string description) {
  Scenario sc;
  sc.name = kind;
  sc.seed = seed;
  sc.description = std::move(description);
  sc.meta.program.kind = kind;
  sc.meta.id = "sim-" + kind + "-s" + std::to_string(seed);
  sc.meta.reference = dsp::Reference{"ideal", {"x", "y", "z"}};
  for (int s = 0; s < 2; ++s) sc.truth[s].spec = sc.meta.sensors[s];
  return sc;
}

// Single-axis programs on x with a 0.5 s dwell (step and positioning).
Scenario axis_scenario(const std::string& kind, std::vector<double> targets_mm, double feed_mm_min, int runs, std::uint64_t seed,
                       std::string description) {
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

Scenario circle_scenario(double radius_mm, double feed_mm_min, int repeats, const std::string& direction, std::uint64_t seed) {
  Scenario sc = base_scenario("circle", seed,
                              "R" + std::to_string(radius_mm) + " circle F" + std::to_string(feed_mm_min) + " x" + std::to_string(repeats) +
                                  " " + direction + ", ideal machine, data-sheet sensors");
  auto& p = sc.meta.program;
  p.plane = "xy";
  p.radius_mm = radius_mm;
  p.feed_mm_min = feed_mm_min;
  p.repeats = repeats;
  p.direction = direction;
  sc.meta.id = "sim-circle-r" + std::to_string(static_cast<int>(radius_mm)) + "-f" + std::to_string(static_cast<int>(feed_mm_min)) +
               "-s" + std::to_string(seed);
  sc.truth[1].temp_c = 20.5;
  return sc;
}

Scenario step_scenario(double from_mm, double to_mm, double feed_mm_min, int runs, std::uint64_t seed) {
  return axis_scenario("step", {from_mm, to_mm}, feed_mm_min, runs, seed,
                       "x step " + std::to_string(from_mm) + " -> " + std::to_string(to_mm) + " mm, ideal machine");
}

Scenario positioning_scenario(const std::vector<double>& targets_mm, int runs, double feed_mm_min, std::uint64_t seed) {
  return axis_scenario("positioning", targets_mm, feed_mm_min, runs, seed, "ISO 230-2 linear cycle on x, ideal machine");
}

dsp::Run simulate(const Scenario& sc) {
  const dsp::Acquisition& acq = sc.meta.acquisition;
  if (!(acq.fs_hz > 0.0)) throw dsp::InputError("simulate: fs_hz must be positive");
  if (sc.oversample < 1) throw dsp::InputError("simulate: oversample must be >= 1");
  if (!(sc.daq_delay_samples_true >= 0.0)) throw dsp::InputError("simulate: DAQ delay must not be negative");

  dsp::Run run;
  run.meta = sc.meta;
  run.meta.format = "eical-run/1";
  if (run.meta.program.gcode.empty()) run.meta.program.gcode = gcode::program_gcode(run.meta.program);
  const nc::Trajectory tr = nc::interpolate_gcode(run.meta.program.gcode, run.meta.id + ".ngc", sc.limits);

  const double fs = acq.fs_hz;
  const auto n_frames = static_cast<std::size_t>(std::ceil(tr.duration_s() * fs)) + 1;
  const int ov = sc.oversample;
  const double h = 1.0 / (fs * ov);
  const auto n_internal = static_cast<std::size_t>(n_frames) * static_cast<std::size_t>(ov) + 1;
  const double g = sc.meta.site.g_mps2;

  run.frames.resize(n_frames);
  for (std::size_t n = 0; n < n_frames; ++n) {
    auto& f = run.frames[n];
    f.sample_index = static_cast<std::int64_t>(n);
    const Eigen::Vector3d p = tr.at(static_cast<double>(n) / fs).pos_mm;
    for (int a = 0; a < 3; ++a) f.cmd_mm[a] = f.ref_mm[a] = p[a];
    f.temp_c[0] = static_cast<float>(sc.truth[0].temp_c);
    f.temp_c[1] = static_cast<float>(sc.truth[1].temp_c);
  }
  for (const auto& t : tr.triggers()) {
    const auto n = static_cast<std::size_t>(std::clamp<long long>(std::llround(t.t_s * fs), 0, static_cast<long long>(n_frames - 1)));
    run.frames[n].trigger = t.code;
  }
  run.channels.ref[0] = run.channels.ref[1] = run.channels.ref[2] = true;
  run.channels.psd_count = 0;
  run.meta.psd.clear();

  std::mt19937_64 rng(sc.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double full_scale = std::ldexp(1.0, acq.adc_bits - 1);
  std::vector<double> y(n_internal);  // PT2 output of one channel on the internal grid, in g

  for (int s = 0; s < 2; ++s) {
    const dsp::SensorSpec& t = sc.truth[s].spec;
    const std::vector<std::string>& moved = s == 0 ? sc.meta.machine.table_axes : sc.meta.machine.head_axes;
    const double sign = s == 0 ? -1.0 : 1.0;  // the table moves against the relative motion
    const Eigen::Matrix3d to_sensor = t.to_machine.inverse();
    auto specific_force_g = [&](double time_s) {
      const Eigen::Vector3d a_rel = tr.at(time_s).acc_mm_s2 / 1000.0;  // m/s²
      Eigen::Vector3d a = Eigen::Vector3d::Zero();
      for (int ax = 0; ax < 3; ++ax)
        if (contains(moved, ax)) a[ax] = sign * a_rel[ax];
      const Eigen::Vector3d f = a + Eigen::Vector3d(0.0, 0.0, g);
      return Eigen::Vector3d(to_sensor * f / g);
    };
    const double sigma_g = sc.noise ? t.noise_ug_per_rthz * 1e-6 * std::sqrt(fs) : 0.0;
    for (int ax = 0; ax < 3; ++ax) {
      Pt2 pt2(t.f0_hz, t.zeta, h);
      pt2.settle(specific_force_g(0.0)[ax]);
      y[0] = pt2.output();
      for (std::size_t k = 1; k < n_internal; ++k)
        y[k] = pt2.step(specific_force_g((static_cast<double>(k) - 0.5) * h)[ax]);  // input mid-step
      for (std::size_t n = 0; n < n_frames; ++n) {
        // The DAQ's linear-phase filter delays every channel by d samples.
        const double pos = (static_cast<double>(n) - sc.daq_delay_samples_true) * ov;
        double a_g;
        if (pos <= 0.0) {
          a_g = y[0];
        } else {
          const auto i0 = static_cast<std::size_t>(pos);
          const double frac = pos - static_cast<double>(i0);
          a_g = i0 + 1 < n_internal ? y[i0] + frac * (y[i0 + 1] - y[i0]) : y[n_internal - 1];
        }
        const double noise = sigma_g > 0.0 ? sigma_g * unit(rng) : 0.0;
        // Static model (6-4), v1 subset.
        const double u_volt = t.k1_v_per_g[ax] * (a_g + t.bias_g[ax] + t.k2_g_per_g2[ax] * a_g * a_g +
                                                  t.k3_g_per_g3[ax] * a_g * a_g * a_g + noise);
        double counts = std::round(u_volt / acq.adc_lsb_volt) + static_cast<double>(acq.adc_offset_counts);
        auto& f = run.frames[n];
        if (counts > full_scale - 1 || counts < -full_scale) {
          counts = std::clamp(counts, -full_scale, full_scale - 1);
          f.flags |= dsp::frame_flag::accel_saturated;
        }
        f.accel_counts[3 * s + ax] = static_cast<std::int32_t>(std::lround(counts));
      }
    }
  }
  run.truth_toml = truth_toml(sc, tr);
  return run;
}

}  // namespace eical::sim
