#pragma once
// Metadata of a recorded run (eical-run/1, docs/run-format.md) as plain data.
// Parsing and writing live in drivers/run_io; dsp only reads these values.
#include "dsp/core/program_kind.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/core/work_envelope.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace eical::dsp {

struct Acquisition {
  double fs_hz = kDefaultFs_hz;
  int adc_bits = 24;
  double adc_lsb_volt = 1.1920929e-6;  // 20 V span / 2^24
  std::int64_t adc_offset_counts = 0;
  double daq_group_delay_samples = 38.8;  // nominal (data sheet)
  // The head's channels lag the table's by this much more (a skew between the DAQ's
  // channels; 0 on the data sheet, found by eical explain; run.toml writes it when set).
  double daq_skew_head_samples = 0.0;
};

struct Site {
  double latitude_deg = 51.3;
  double heading_deg = 0.0;  // azimuth of machine +X, clockwise from north
  double g_mps2 = 9.8113;
};

// Which machine axes are moved by the table and which by the head ("x", "y", "z").
struct MachineLayout {
  std::string name = "sim-maho";
  std::vector<std::string> table_axes = {"x", "y"};
  std::vector<std::string> head_axes = {"z"};
};

// Data-sheet (nominal) sensor values as in [sensors.table] / [sensors.head].
struct SensorSpec {
  std::string model = "SF3000L";
  Eigen::Matrix3d to_machine = Eigen::Matrix3d::Identity();  // rows machine X,Y,Z; cols sensor axes
  Eigen::Vector3d k1_v_per_g{1.235, 1.228, 1.234};
  Eigen::Vector3d k2_g_per_g2{-7.05e-4, -8.56e-4, -1.57e-3};
  Eigen::Vector3d k3_g_per_g3{6.45e-4, 1.06e-3, -1.49e-3};
  Eigen::Vector3d bias_g{0.044, 0.010, -0.012};
  double tc_k1_ppm_per_c = 70.0;
  double tc_bias_ug_per_c = 100.0;
  double f0_hz = 1000.0;
  double zeta = 0.707;
  // Squeeze-film damping that grows with the acceleration, ζ = ζ0 (1 + zeta_per_g |a|/g)
  // (ch. 8.3.1); 0 on the data sheet, found by eical explain (written when set).
  double zeta_per_g = 0.0;
  double noise_ug_per_rthz = 0.4;
  // Bias random walk (6-5, 6-6), µg/√s: the SF3000L's units walk by 0.12–0.3, the rms of
  // that range. The uncertainty's draws integrate it (error_field.hpp); a sensor whose data
  // sheet or identification says otherwise sets it (run.toml [sensors.*]).
  double bias_walk_ug_per_rts = 0.22;
  double temp_ref_c = 20.0;
};

struct PsdSpec {
  std::string measures = "x";        // relative-position axis it measures
  double center_mm[2] = {0.0, 0.0};  // (x, y) of the strip centre, relative coordinates
  double length_mm = 10.0;
  double width_mm = 0.5;
  double lockin_tau_s = 2.0e-5;
};

// [program]: which keys are meaningful depends on kind (see run-format.md).
struct Program {
  ProgramKind kind = ProgramKind::circle;
  std::string plane = "xy";
  double center_mm[2] = {0.0, 0.0};
  double radius_mm = 10.0;
  double feed_mm_min = 2500.0;
  std::string direction = "ccw";  // cw | ccw | both (ccw first, then cw back)
  int repeats = 1;
  // Circle: the evaluated arc (ISO 230-4 partial arc when below 360°) and, for a partial
  // arc, where it begins (plane angle from the plane's first axis, counter-clockwise).
  double arc_deg = 360.0;
  std::optional<double> arc_start_deg;
  std::string axis = "x";          // step / positioning
  std::vector<double> targets_mm;  // step / positioning
  int runs = 1;                    // step / positioning
  double dwell_s = 0.0;
  double corner_mm[2] = {0.0, 0.0};  // rectangle
  double size_mm[2] = {0.0, 0.0};    // rectangle
  std::string gcode;                 // NC source that produced the run, if any
};

struct Reference {
  std::string kind;
  std::vector<std::string> axes;
};

// [setpoint]: where cmd_* came from when the NC is not eical's own, and how well it was
// aligned with the DAQ clock (written by eicald; see docs/service.md, "The NC's set-point").
struct SetPointOrigin {
  std::string source;  // "servo_stream" (another NC's servo-rate positions) | "program" (eical's interpolator)
  // servo_stream: fractional servo cycle number at the run's first sample (the two clocks'
  // mapping, from their minimum-filtered arrival times).
  double servo_cycle_at_first_sample = 0.0;
  double servo_rate_hz = 0.0;
  int program_number = -1;  // M101's P word (or the default program); -1 = none named
  // program: DAQ time − program time of the first motion block from the marks alone and
  // after the cross-correlation, number of motion blocks aligned separately and the spread
  // (max − min) of their offsets.
  double marks_offset_s = 0.0;
  double offset_s = 0.0;
  int blocks = 0;
  double block_offset_spread_s = 0.0;
  // Both: cross-correlation of measured against commanded acceleration over the motion,
  // after the alignment: lag (measured later = positive; servo lag plus what the clocks
  // missed), correlation at the peak, and the residual RMS(measured − commanded) relative to
  // RMS(commanded) — the alignment's residual.
  double lag_s = 0.0;
  double correlation = 0.0;
  double residual_ratio = 0.0;
};

struct RunMeta {
  std::string format = "eical-run/1";
  std::string id;
  std::string created;  // RFC 3339 text as written in run.toml
  Acquisition acquisition;
  Site site;
  MachineLayout machine;
  SensorSpec sensors[2];  // index by Sensor: table, head
  // A triplex whose every field is empty in samples.csv is not there (run-format.md, "One
  // sensor"): the relative acceleration is the other sensor's absolute one.
  bool sensor_present[2] = {true, true};
  std::vector<PsdSpec> psd;
  Program program;
  std::optional<Reference> reference;
  std::optional<SetPointOrigin> setpoint;
  // [envelope]: the machine's work envelope the run was made within (written when known:
  // eical simulate, eicald from its config).
  std::optional<WorkEnvelope> envelope;
};

}  // namespace eical::dsp
