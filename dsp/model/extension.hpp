#pragma once
// The significant sensor effects made part of the model: the run's sensors and DAQ delay
// with them applied — what a calibration file (eical-sensor-cal/1, method "explain")
// stores and the pipeline then compensates with. Scale, mounting and cross-axis terms go
// into the sensor's to_machine ((I + E)⁻¹ · data sheet), nonlinearity into k2/k3, the
// timing into ζ (f0 kept: 1/ω0² is below what a run can see), damping growing with |a|
// into zeta_per_g, the delay and the head's skew into the DAQ's. What the pipeline does
// not take from a calibration (bias drift, temperature coefficients, Coriolis — a switch of
// its own) is listed in `notes`.
#include "dsp/core/run_meta.hpp"
#include "dsp/model/explain.hpp"

#include <string>
#include <vector>

namespace eical::dsp::model {

struct Extension {
  SensorSpec sensors[2];
  double daq_group_delay_samples = 38.8, daq_skew_head_samples = 0.0;
  bool delay_changed = false, skew_changed = false;
  std::vector<std::string> notes;
};

Extension extend_sensors(const RunMeta& meta, const std::vector<ExplainedEffect>& effects);

}  // namespace eical::dsp::model
