#pragma once
// On-site identification of the sensors (ch. 8.2, without a KGM): from a short program
// that swings the axes across the PSD strips (sim/gcode identify_program), estimate what
// the data sheet gets wrong — per sensor the 3×3 error of its acceleration in machine
// axes (scale on the diagonal, misalignment and cross-axis sensitivity off it, (6-18)),
// the damping term 2ζ/ω0 of (6-38), the bias at rest — and the DAQ delay, and store them
// as the calibration the pipeline compensates with from then on.
//
// What is fitted, per machine axis, in one augmented Kalman filter (augmented_filter.hpp)
// over the integrated motion as the pipeline makes it (data-sheet parameters):
//   δa_i = Σ_j E_ij a_j                  scale (E_ii) and cross terms (E_ij) of the sensor
//                                        that moves axis j (8-3: scale = p_ref/p_in)
//   δx_i += Δc1 · v_i                     Δ(2ζ/ω0) of the sensor moving axis i (8-5)
// against
//   every standstill: velocity zero (ZUPT; each partial move its own bias, ch. 8.3.2)
//   every standstill: position = set-point + x0_i + b_i · direction/2 (rest offset and
//                     backlash of the machine, fitted alongside)
//   every lit PSD sample: position = the strip's reading + o_k (its mounting offset)
// 1/ω0² (acceleration × 25 ns² ≈ 0.05 µm at 2 m/s²) is below what a run can see and keeps
// its data-sheet value. The DAQ delay is the time shift of the PSD readings (which pass the
// DAQ filter) behind the set-point — which includes the axes' servo lag — or, when the run
// has a reference instrument, behind that (the delay itself). The data sheet's delay is
// kept unless the reference is there or the caller accepts the set-point's figure.
#include "dsp/core/run.hpp"
#include "dsp/core/sensor_model_covariance.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace eical::dsp::identify {

struct IdentifyOptions {
  double rest_sigma_um = 0.5;        // the machine at a standstill against its set-point (repeatability)
  int psd_every = 10;                // use every n-th lit PSD sample (they are strongly correlated)
  int iterations = 2;                // re-run with the estimate, fit what is left
  bool delay_from_setpoint = false;  // accept the PSD-vs-set-point delay (includes servo lag)
  bool against_reference = false;    // fit to the reference instrument instead (comparison)
  int reference_every = 50;
  double reference_sigma_um = 0.1;
  // The RMS the data sheet and the identified model leave (psd_rms_*, rest_rms_*): two more
  // integrations of the run, which the covariance does not read (eical plan's typical
  // identification wants the covariance only).
  bool compare_with_datasheet = true;
};

struct Estimate {
  double value = 0.0, sigma = 0.0;
  bool fitted = false;
};

struct SensorEstimate {
  bool moved = false;    // it carried an axis that moved: something to identify
  Estimate error[3][3];  // E_ij: measured = (I + E) · true, machine axes (columns: its own axes)
  Estimate damping_s;    // Δ(2ζ/ω0) = data sheet − identified, s
  Eigen::Vector3d rest_bias_g = Eigen::Vector3d::Zero();  // bias at the first standstill, sensor axes, gravity removed
};

struct DelayEstimate {
  bool valid = false;
  double samples = 0.0, sigma = 0.0;  // identified delay (DAQ delay for "reference"; + servo lag for "set-point")
  std::string against;                // "set-point" | "reference"
  int fixes = 0;
  bool mounting_assumed = false;  // a strip crossed at one speed one way: taken where run.toml puts it
};

struct Identification {
  SensorEstimate sensor[2];  // table, head
  Estimate rest_offset_um[3], backlash_um[3];
  std::vector<Estimate> psd_offset_um;     // per strip
  std::vector<Estimate> psd_nonlinearity;  // per strip: nl of u (1 + nl (2u/L)²), where its axis moved
  DelayEstimate delay_setpoint, delay_reference;
  // The calibration to use from now on: the run's sensors with the estimate applied.
  SensorSpec sensors[2];
  StaticCalibration calibration[2];
  double daq_group_delay_samples = 38.8;
  bool delay_identified = false;
  // How well the identified model explains the observations (PSD fixes, rest positions).
  double psd_rms_before_um = 0.0, psd_rms_after_um = 0.0;
  double rest_rms_before_um = 0.0, rest_rms_after_um = 0.0;
  std::size_t psd_observations = 0, rest_observations = 0, standstills = 0;
  // Per machine axis, the mean normalised innovation² of its position observations (PSD or
  // reference, set-point at rest): 1 where the filter's noise and sensor model hold.
  double position_nis[3] = {0.0, 0.0, 0.0};
  int iterations = 0;
  std::string method;  // "psd" (PSD fixes + set-point at rest) | "ref"
  std::vector<std::string> notes;
  // The calibration's covariance (sensor_model_covariance.hpp layout): each axis' filter
  // block for the E terms it fitted, the damping terms and the delay; the data sheet's
  // tolerance where nothing was identified (the data sheet is kept there).
  dsp::SensorModelCovariance covariance;
  // Strip crossings and their distinct speeds (mm/s), standstills in the motion.
  std::size_t strip_crossings = 0;
  std::vector<double> crossing_speeds_mm_s;
};

// Throws InputError when the run cannot identify the sensors: no motion, fewer than two
// standstills in the motion, no PSD strips (unless against a reference) or strips crossed
// at one speed only (a scale error and a damping error then look alike: the identification
// program crosses at 2, 4 and 6.5 m/min).
Identification identify_sensors(const Run& run, const IdentifyOptions& options = {});

// The parameters an identification fitted less certainly than the data sheet promises
// (the σ its covariance carries above the data sheet's u): a calibration with them would
// be worse than none.
std::vector<std::string> less_certain_than_datasheet(const Identification& id,
                                                     const dsp::SensorModelCovariance& datasheet);

// The run's metadata with an identification applied (what the pipeline then uses).
void apply_identification(const Identification& id, RunMeta& meta, PipelineConfig* config = nullptr);

}  // namespace eical::dsp::identify
