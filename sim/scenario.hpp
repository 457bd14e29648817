#pragma once
// Everything one simulated run depends on. Nominal values (what eical is told: data sheet,
// program) live in `meta`; the true values the data are generated with live beside them,
// so a scenario can make reality differ from the data sheet (and truth.toml says how).
// Every effect of docs/run-format.md maps onto fields here; all default to "off"
// (an ideal machine that follows the set-point, data-sheet sensors, a nominal DAQ).
#include "dsp/core/run_meta.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/nc/klipper_excitation.hpp"
#include "sim/nc/trajectory.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace eical::sim {

// Slowly warming sensor case: T(t) = t0 + rise·(1 − exp(−t/tau)).
struct CaseTemperature {
  double t0_c = 20.0;
  double rise_c = 0.0;
  double tau_s = 600.0;
  [[nodiscard]] double at(double t_s) const;
};

// True sensor: the data-sheet keys (spec) plus what the data sheet does not list.
struct SensorTruth {
  dsp::SensorSpec spec;  // true k1, k2, k3, bias, tc, f0, zeta, noise, mounting
  // (6-4) cross terms in g: row = sensor axis responding, column = axis across it.
  Eigen::Matrix3d k_cross_g_per_g = Eigen::Matrix3d::Zero();    // k_x a_y, k_y a_x, ...
  Eigen::Matrix3d k_cross2_g_per_g2 = Eigen::Matrix3d::Zero();  // k_zy a_z a_y, ...: (i,j) = a_i·a_j on axis row
  double zeta_per_g = 0.0;           // squeeze-film damping: ζ = ζ0 (1 + zeta_per_g |a|/g) (ch. 8.3.1)
  double bias_rw_ug_per_rts = 0.0;   // bias random walk (6-5, 6-6)
  double bias_step_ug = 0.0;         // bias jump at the start of every move (ch. 8.3.2), alternating sign
  double bias_drift_ug_per_s = 0.0;  // linear bias drift
  CaseTemperature temperature;
  // A mounting that differs from run.toml's by more than a small rotation (a sign flip, a
  // swap of two axes, a mirror), as an axes map ("y,x,z", Klipper's axes_map notation):
  // spec.to_machine already holds it; this only names it for truth.toml. Empty: none.
  std::string axes_map;
};

// Position loop of one axis: v = ff·v_cmd + Kv·(cmd − x), optionally through a first-order
// velocity loop (time constant) which makes the loop second order. kv_per_s = 0: ideal.
struct AxisServo {
  double kv_per_s = 0.0;
  double feedforward = 0.0;
  double velocity_tau_s = 0.0;
};

struct ReversalSpike {
  double amp_um = 0.0;   // peak lag after a reversal
  double tau_ms = 15.0;  // time to the peak; decays over a few tau
};

struct CyclicError {
  double amp_um = 0.0;
  double pitch_mm = 10.0;
  double phase_deg = 0.0;
};

// Axis bends sideways: deviation along `direction` = bow·(1 − u²), u = −1..1 over the span.
struct Straightness {
  int direction = -1;  // 0, 1, 2 = x, y, z; −1 = none
  double bow_um = 0.0;
  double span_mm[2] = {-10.0, 10.0};
};

// Below `below_mm_min` static friction holds the slide until its lag behind the set-point
// reaches amp (it breaks free there), then it slips forward in `slip_ms` and sticks again.
// The lag peaks a little above amp while the slide gathers speed. At standstill it stays
// where it stuck (a positioning error); above the creep speed it breaks free.
struct StickSlip {
  double amp_um = 0.0;
  double below_mm_min = 100.0;
  double slip_ms = 2.0;
};

struct MachineErrors {
  AxisServo servo[3];
  double backlash_um[3] = {0, 0, 0};
  ReversalSpike spike[3];
  double squareness_urad[3] = {0, 0, 0};  // xy, yz, zx: positive = angle between axes > 90°
  double scale_ppm[3] = {0, 0, 0};
  CyclicError cyclic[3];
  Straightness straightness[3];  // of axis x, y, z
  StickSlip stick_slip[3];
};

struct Tone {
  double freq_hz = 100.0;
  Eigen::Vector3d amp_mg = Eigen::Vector3d::Zero();  // peak, machine axes
  double phase_deg = 0.0;
};

// A structural mode driven by the axes' commanded acceleration:
// m'' + 2ζω m' + ω² m = gain·a_cmd (per machine axis).
struct DriveMode {
  double freq_hz = 9.0;
  double zeta = 0.03;
  Eigen::Vector3d gain = Eigen::Vector3d::Zero();  // dimensionless
};

// Head and table vibrate together (absolute motion, no relative motion).
struct CommonVibration {
  std::vector<Tone> tones;
  Eigen::Vector3d broadband_rms_mg = Eigen::Vector3d::Zero();
  double band_hz[2] = {20.0, 800.0};
  DriveMode mode;  // the machine rocking on its foundation
  [[nodiscard]] bool on() const;
};

struct DaqTruth {
  // false: a digital MEMS sensor that samples its own low-pass output at fs, with no
  // anti-alias filter before it (what lies above fs/2 aliases, as on a real chip); the
  // group delay is then a pure delay.
  bool anti_alias_filter = true;
  double group_delay_samples = 38.8;
  double skew_head_samples = 0.0;  // head channels later than table
  std::int64_t offset_counts[6] = {0, 0, 0, 0, 0, 0};
  double noise_nv_per_rthz = 0.0;  // electronic noise at the ADC input, two-sided
};

// The laser spot on a 1-D PSD strip: what the data sheet of run.toml [[psd]] does not say.
struct PsdTruth {
  double spot_mm = 0.03;
  double full_scale_v = 2.0;  // i1 + i2 with the whole spot on the strip
  double nonlinearity = 0.0;  // u_meas = u (1 + nl (2u/L)²)
  double noise_v_per_rthz = 6e-7;
};

// Reference instrument (cross-grid encoder): scale error and interpolation error within a
// signal period, 1 nm resolution.
struct ReferenceTruth {
  double scale_ppm[3] = {0, 0, 0};
  double interp_nm[3][2] = {{0, 0}, {0, 0}, {0, 0}};  // 1st and 2nd harmonic per axis
  double interp_phase_deg[3][2] = {{0, 0}, {0, 0}, {0, 0}};
  double signal_period_um = 4.0;
  double resolution_nm = 1.0;
};

// A structural mode between the drive and the measured point (run-format.md,
// machine.resonance): the tool follows the drive through
//   m'' + 2ζω m' + ω² m = −gain · (direction · a_drive)
// along the unit `direction`; the measured point moves by m·direction on top of the drive.
struct StructuralMode {
  double frequency_hz = 50.0;
  double damping_ratio = 0.02;
  double gain = 0.0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

struct Resonance {
  std::vector<StructuralMode> modes;
  int part = 1;  // dsp::Sensor index of the part whose measured point rings: 0 table, 1 head
  [[nodiscard]] bool on() const;
};

// Klipper's resonance test instead of a G-code program (sim/nc/klipper_excitation): one
// axis (or direction) swept from the first sample to the last unless lead_in_s/tail_s
// add rest around it.
struct SweepExcitation {
  bool on = false;
  nc::KlipperTest test;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  Eigen::Vector3d start_mm = Eigen::Vector3d::Zero();
  double lead_in_s = 0.0;
  double tail_s = 0.0;
};

// The default of Scenario::max_duration_s: 40 minutes, 15 GB (the 31-minute run of the
// long-recording bench fits).
inline constexpr double kMaxSimulatedS = 2400.0;

struct Scenario {
  std::string name = "baseline";
  std::string description;
  std::uint64_t seed = 1;
  dsp::RunMeta meta;     // nominal metadata written to run.toml; program.gcode may be empty
  SensorTruth truth[2];  // table, head
  DaqTruth daq;
  MachineErrors machine;
  CommonVibration common_vibration;
  DriveMode differential_vibration;      // head against table: real relative motion (a mode)
  std::vector<Tone> differential_tones;  // ... and forced tones (spindle, drive): amp_mg is the
                                         // relative acceleration, the displacement amp/ω²
  Resonance resonance;                   // structural modes between drive and measured point
  bool coriolis = false;                 // Earth rate from [site] latitude and heading
  std::vector<PsdTruth> psd;             // one per meta.psd strip (defaults when shorter)
  ReferenceTruth reference;
  nc::MachineLimits limits;
  SweepExcitation sweep;  // on: runs Klipper's resonance test, not meta.program.gcode
  int oversample = 10;    // internal rate = oversample · fs (≥ 100 kHz at 10 kHz)
  // The longest run simulate() makes, at 100 kHz internal samples (a finer grid shortens it
  // in proportion): memory grows with the run, about 0.4 GB a minute at 10 kHz, so a
  // program longer than this is refused before anything is allocated.
  double max_duration_s = kMaxSimulatedS;
  bool noise = true;  // white sensor noise (quantisation is always on: for a
                      // near-ideal ADC use adc_bits = 32 and a tiny adc_lsb_volt)
  // Effects the scenario injected on purpose (names of run-format.md) and those present
  // only at tolerance level; truth.toml lists both. Empty `present`: derived from the
  // parameters that differ from nominal.
  std::vector<std::string> effects_present;
  std::vector<std::string> effects_background;
};

// The issue-2 demo circle: R = 10 mm, F = 2500 mm/min, 5 repeats ccw in XY, both sensors
// with data-sheet values equal to the truth, noise 0.4 µg/√Hz, 10 kHz.
Scenario circle_scenario(double radius_mm = 10.0, double feed_mm_min = 2500.0, int repeats = 5,
                         const std::string& direction = "ccw", std::uint64_t seed = 1);

// Step test as in the sample runs: x from targets[0] to targets[1] and back, `runs` times.
Scenario step_scenario(double from_mm = 0.0, double to_mm = 50.0, double feed_mm_min = 3250.0, int runs = 2,
                       std::uint64_t seed = 1);

// ISO 230-2 linear cycle on x over `targets_mm` (ascending), `runs` bidirectional runs.
Scenario positioning_scenario(const std::vector<double>& targets_mm, int runs = 5, double feed_mm_min = 2000.0,
                              std::uint64_t seed = 1);

// Rectangle `size_a_mm` × `size_b_mm` from the origin in `plane`, exact stop at the corners.
Scenario rectangle_scenario(double size_a_mm = 50.0, double size_b_mm = 50.0, double feed_mm_min = 6500.0,
                            const std::string& plane = "xy", int repeats = 1, std::uint64_t seed = 1);

// A scenario running the given G-code (a free-form program or any generated one).
Scenario gcode_scenario(const std::string& gcode, dsp::ProgramKind kind = dsp::ProgramKind::freeform,
                        std::uint64_t seed = 1);

// PSD configuration B of the sample runs for a circle of radius R about the origin: a strip
// measuring x where the circle crosses −y, one measuring y where it crosses +x (each 10 mm
// long, tangent to the circle: the spot runs along it for millimetres).
std::vector<dsp::PsdSpec> psd_config_b(double radius_mm = 10.0);
// How a ring's strips face the circle. Along the path (configuration B): the spot runs
// along each strip for millimetres and it reads the position along the path. Across the
// path (radial): each strip turned a quarter, the spot crosses its width in milliseconds
// and it reads the radius there, as a ballbar does; the radius is what G is made of, so at
// R50 F4000 with 16 strips the noise bound of G falls from 3.25 to 1.77 µm (eical demo,
// seed 1).
enum class StripFacing { along_path, across_path };
// Configuration B widened to `count` strips (1..dsp::kMaxPsd) around the circle, from where
// it crosses −y counter-clockwise, 360°/count apart (90° for fewer than 4): along the path
// each measures the axis the path runs along more, across it the other (at 45° x and y
// alternate). Along, 2 is configuration B, 4 B and its mirror.
std::vector<dsp::PsdSpec> psd_ring(double radius_mm, int count, StripFacing facing = StripFacing::along_path);
// How strips about a circle centred at the origin face it, by the rule psd_ring places
// them with; nullopt when they are mixed or every one sits at 45° (where both apply).
std::optional<StripFacing> ring_facing(const std::vector<dsp::PsdSpec>& psd);

// On-site identification (sim/gcode identify_program) over the given strips and further
// axes, with those strips in the run.
Scenario identify_scenario(const std::vector<dsp::PsdSpec>& psd, const std::vector<std::string>& axes = {"z"},
                           std::uint64_t seed = 1);
// The same for a whole plan (its swing, feeds and travel).
Scenario identify_scenario(const gcode::IdentifyPlan& plan, std::uint64_t seed);

}  // namespace eical::sim
