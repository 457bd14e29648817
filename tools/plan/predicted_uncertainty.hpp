#pragma once
// `eical plan`: the uncertainty a test will have, before anything moves. The error
// covariance of a measurement depends on its schedule of supports (standstills, strip
// crossings, held axes), the sensors' noise, the DAQ and the sensor model — not on the
// machine's errors — so a simulation of the program on an ideal machine with the given
// sensors, DAQ and PSD strips, analysed like a real run, predicts the U of every figure
// (dsp/analysis/figure_uncertainty.hpp). A program whose headline uncertainty exceeds what
// the test is meant to resolve (dsp/analysis/verdict.hpp) gets the nearest variant that
// does not: strips added, a higher feed (shorter gaps between the supports), a smaller
// radius or travel, down to the thesis' test.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/core/sample_rate.hpp"
#include "sim/scenario.hpp"

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace eical::tools::plan {

struct TestProgram {
  dsp::ProgramKind kind = dsp::ProgramKind::circle;
  std::string plane = "xy", direction = "ccw";
  double radius_mm = 10.0, feed_mm_min = 2500.0, arc_deg = 360.0;
  int repeats = 5;                                              // circle revolutions, rectangle laps
  std::vector<double> targets_mm{0.0, 10.0, 20.0, 30.0, 40.0};  // positioning
  int runs = 5;                                                 // positioning runs, step pairs
  double from_mm = 0.0, to_mm = 50.0;                           // step
  double size_mm[2] = {50.0, 50.0};                             // rectangle
  std::vector<dsp::PsdSpec> psd;                                // the strips on the machine
  double noise_ug_per_rthz = 0.4;                               // each sensor, two-sided
  double fs_hz = dsp::kDefaultFs_hz;                            // the DAQ's rate
  bool identified = false;                                      // sensors identified on site first (eical identify)
  // What the limited figure's U must reach (eical plan --resolve); unset: what the program
  // must resolve (dsp::resolution_limit, a circle's G 10 µm).
  std::optional<double> resolve_um;
};

// "circle R10 F2500 ccw ×5 in xy, 2 PSD strips".
std::string describe(const TestProgram& p);
// Strips for the program: configuration B about a circle, one at mid travel of a 1-D
// test, one per side's middle of a rectangle.
std::vector<dsp::PsdSpec> strips_for(const TestProgram& p);
// A circle's `count` strips facing so (1..16, sim::psd_ring: 2 along the path is
// configuration B); another program's strips_for for 2 and none for 0, and refused for more.
std::vector<dsp::PsdSpec> strips_for(const TestProgram& p, int count,
                                     sim::StripFacing facing = sim::StripFacing::along_path);
// A positioning or step test's two strips at the ends of its travel (on x).
std::vector<dsp::PsdSpec> strips_at_both_ends(const TestProgram& p);
// The program's strips where an identification that stays inside the test's travel can
// cross them: a strip on (or near) a travel's end moved one strip length inside it. A
// circle's strips stay: the circle crosses them where they are, and its identification runs
// on beyond the circle to reach them (identification_plan).
std::vector<dsp::PsdSpec> strips_identification_can_cross(const TestProgram& p);
// The program a recorded run ran (for analyze's suggestion).
TestProgram program_of(const dsp::RunMeta& meta);
// The simulated run of a program on an ideal machine with data-sheet sensors.
sim::Scenario scenario_of(const TestProgram& p, std::uint64_t seed);
// The same program on a machine drawn within the data sheet's tolerances (the background of
// `eical simulate --background` for that seed: sensors, small machine errors, Earth rate).
sim::Scenario scenario_on_drawn_machine(const TestProgram& p, std::uint64_t seed);
// The PSD strips of the machine drawn for `seed`: each its own nonlinearity within the data
// sheet's bound (DatasheetTolerance::psd_nonlinearity), the same for a strip at the same
// place (the identification's strips and a test's are the machine's).
std::vector<sim::PsdTruth> drawn_strips(const std::vector<dsp::PsdSpec>& psd, std::uint64_t seed);
// The identification program (eical gen-nc identify) over the test's strips inside its
// travel (identification_plan.hpp), with the program's sensors and DAQ: how a machine's
// sensors are identified on site before this test.
sim::Scenario identification_scenario(const TestProgram& p, std::uint64_t seed);
// That identification run on `machine` (a scenario_on_drawn_machine of the same seed): its
// sensors, DAQ, machine errors, site and strips, the strips with their nonlinearity.
sim::Scenario identification_on_machine(const TestProgram& p, const sim::Scenario& machine, std::uint64_t seed);
// What that identification leaves the sensor model uncertain by (simulated on data-sheet
// sensors): the covariance a calibration would carry.
dsp::SensorModelCovariance typical_identification(const TestProgram& p);
// Seconds the program runs (from the simulation's set-point).
double duration_s(const dsp::Run& run);

struct Prediction {
  TestProgram program;
  std::map<std::string, double> u_k2;  // scalar figures
  std::string headline, limited;       // result keys (verdict.hpp)
  double limited_u = 0.0, limit = 0.0;
  bool measurable = false;  // U(limited) within what the test is meant to resolve
  double duration_s = 0.0;
};

// Simulates and analyses the program; `draws` Monte Carlo draws. With p.identified the
// sensor model's covariance is `identified` (or typical_identification(p) when not given).
// `screen`: the draws stop after the screen's first ones when U of the limited figure is
// already `margin` times its limit (a variant it stops is not measurable). U from n draws is
// twice a standard deviation estimated from n samples, whose relative standard error is
// 1/√(2(n − 1)), 16 % at 20 draws: a U twice the limit after 20 is six of them above it.
struct Screen {
  int draws = 20;
  double margin = 2.0;
};
Prediction predict(const TestProgram& p, std::uint64_t seed = 1, int draws = 100,
                   const std::optional<dsp::SensorModelCovariance>& identified = std::nullopt,
                   const std::optional<Screen>& screen = std::nullopt);

// The nearest variants of a program, nearest first (the program itself not included): the
// test's own changes with the sensors as they are, then the same after an identification.
std::vector<TestProgram> variants(const TestProgram& p);

// Where the program runs beyond the machine's work envelope ("the program reaches x = ...,
// beyond the x travel ..."), from its set-point; nullopt when it stays within.
std::optional<std::string> outside_envelope(const TestProgram& p, const dsp::WorkEnvelope& envelope);
// Seconds the program runs, from its set-point (nothing simulated).
double program_duration_s(const TestProgram& p);

// How the search for a measurable variant looks, and what it reports while it does.
struct SearchOptions {
  double max_duration_s = 60.0;  // variants that run longer are not tried
  int draws = 60;
  dsp::WorkEnvelope envelope;  // variants beyond it are not tried
  // No simulation starts after it (one that has started finishes: each is at most
  // max_duration_s of program).
  std::optional<std::chrono::steady_clock::time_point> deadline;
  // Before each simulation: the n-th of `of` variants (0: the on-site identification the
  // identified variants share).
  std::function<void(int n, int of, const TestProgram&)> progress;
  // The machine's own calibration (plan --calibration): every identified variant uses its
  // covariance instead of a simulated identification.
  std::optional<dsp::SensorModelCovariance> calibration;
};

// What became of each variant.
enum class Outcome { measurable, not_measurable, too_long, outside_envelope, not_reached };
struct Tried {
  TestProgram program;
  Outcome outcome = Outcome::not_reached;
  double limited_u = 0.0;  // predicted U of the limited figure (measurable, not_measurable)
};
struct Search {
  std::optional<Prediction> found;  // the first measurable variant, nearest first
  std::vector<Tried> tried;         // every variant up to it, and those the deadline left
  bool deadline_passed = false;     // variants were left (Outcome::not_reached)
};
Search search_measurable(const TestProgram& p, const SearchOptions& o);

// The first variant (nearest first) whose predicted U is within the limit; variants that
// run longer than `max_duration_s` or beyond the envelope are not tried. nullopt when none is.
std::optional<Prediction> nearest_measurable(const TestProgram& p, double max_duration_s = 60.0, int draws = 60,
                                             const dsp::WorkEnvelope& envelope = {});

}  // namespace eical::tools::plan

namespace eical::tools::plan {

// For a run whose verdict is not_measurable: the nearest measurable test, or why none is
// proposed, appended to its verdict reasons.
void suggest_measurable_test(const dsp::Run& run, dsp::Analysis& a);

}  // namespace eical::tools::plan
