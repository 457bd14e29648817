#pragma once
// A synthetic recorded run from a scenario, physics in this order, on an internal grid
// at oversample·fs (≥ 100 kHz):
//   NC interpolator (set-point) → machine: per-axis position loop and axis errors
//   (sim/machine/axis_motion), errors between axes (sim/machine/geometry), the head's
//   mode against the table (real relative motion) → absolute acceleration of table and
//   head (set-point acceleration plus the second difference of their deviations, so the
//   double integral of what the sensors see is exactly the relative position the
//   reference reads) + common vibration + Earth-rate Coriolis → specific force with
//   gravity in each sensor's true mounting → PT2 and the fast static model per sensing
//   element (sim/sensor/sensing_element) → DAQ decimation filter with the true group
//   delay (head channels skewed) → slow static terms (bias, drift, random walk,
//   temperature of k1 and bias), white sensor and electronic noise → ADC with offsets.
//   PSD strips see the relative position through their lock-in and the same DAQ filter;
//   the reference reads the relative position undelayed with its own small errors.
//
// Conventions the DSP pipeline relies on:
//  * specific force f = a − g_vec with g_vec = (0, 0, −g): a sensor at rest, z up, reads +1 g;
//  * sensor axes = to_machine⁻¹ · f (to_machine maps sensor axes to machine axes);
//  * U = k1 (a_g + bias + k2 a_g² + k3 a_g³ + cross terms + n), counts = round(U / lsb) + offset;
//  * output sample n holds the analog signal at n/fs − d/fs (d = DAQ group delay in
//    samples); cmd_mm and ref_mm at sample n are the set-point and the reference reading
//    at n/fs (not delayed); triggers sit on the sample nearest their time.
// Deterministic for a given seed; each random process (sensor noise per channel, bias
// walk, broadband vibration, PSD noise) has its own stream, so switching one effect on
// does not change the noise of the others.
#include "dsp/core/run.hpp"
#include "dsp/core/stream_seed.hpp"
#include "sim/nc/set_point.hpp"
#include "sim/scenario.hpp"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <vector>

namespace eical::sim {

dsp::Run simulate(const Scenario& scenario);

// What another system's capture of the same run holds (sim/regimes/capture_clock): frame
// n truly taken at n/fs + jitter_s[n], with the same slow terms, noise and ADC as the
// run's frame n — only the sampling time differs, so the run itself is unchanged.
struct JitteredCapture {
  std::vector<double> jitter_s;                                       // in: one per frame
  std::vector<std::array<std::int32_t, dsp::kAccelChannels>> counts;  // out
};

// The same, also returning the true relative position at every frame (mm) — what an
// ideal reference would read — for validation and tests, and optionally the capture.
dsp::Run simulate(const Scenario& scenario, std::vector<Eigen::Vector3d>* true_rel_mm,
                  JitteredCapture* capture = nullptr);

// The same for a set-point from elsewhere (another NC's servo-rate positions); the
// program in scenario.meta is written to run.toml as it is (its gcode is not run).
dsp::Run simulate(const Scenario& scenario, const nc::SetPoint& set_point,
                  std::vector<Eigen::Vector3d>* true_rel_mm = nullptr, JitteredCapture* capture = nullptr);

// Throws InputError when the set-point runs longer than the scenario's budget
// (Scenario::max_duration_s): simulate() checks it before allocating; a caller that sizes
// buffers per frame itself checks it first.
void check_budget(const Scenario& scenario, const nc::SetPoint& set_point);

// The set-point a scenario runs: its Klipper sweep, or its program's G-code interpolated.
std::unique_ptr<nc::SetPoint> scenario_set_point(const Scenario& scenario);

// An independent random stream per purpose, derived from the scenario's seed.
using dsp::stream_seed;

}  // namespace eical::sim
