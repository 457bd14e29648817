#pragma once
// What the nominal model (data-sheet sensors, an ideal machine following its set-point)
// gets wrong about one recorded run, as residual channels at 1 kHz:
//   sensor  = inertial − reference instrument  (what the sensor model gets wrong)
//   machine = reference − set-point            (what the ideal machine gets wrong)
//   total   = inertial − set-point             (both, when nothing else is there)
// The inertial path is the pipeline's with the nominal model: ZUPT and smoother, no PSD
// fixes (the strips are a reference here, not a support). Per axis the reference is the
// instrument's column when there is one, else the PSD readings where a strip is lit, else
// only the set-point (run-format.md / results.md: "ref", "psd", "cmd").
//
// The sensor side is fitted through the integration's noise model (kf_selection.hpp): the
// tracks hold the integrated motion as it was integrated, against each axis' reference.
#include "dsp/core/run.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/model/kf_selection.hpp"
#include "dsp/pipeline/pipeline.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace eical::dsp::model {

struct Channel {
  std::string name;               // "sensor" | "machine" | "total"
  std::vector<int> sample, axis;  // each row: decimated sample and machine axis
  Eigen::VectorXd residual_um;    // per row
  Eigen::VectorXd sigma_um;       // per row: the noise the row carries (weights)
  [[nodiscard]] Eigen::Index rows() const { return residual_um.size(); }
};

struct RunResiduals {
  std::string run_id, reference;  // "ref" | "psd" | "cmd"
  double fs_hz = kDefaultFs_hz, dt_s = 1e-3;
  int n = 0;                       // decimated samples
  std::vector<std::size_t> trace;  // decimated → aligned trace position
  std::array<bool, 3> moving{}, has_ref{}, has_psd{};
  std::array<std::string, 3> axis_reference{};  // per axis: "ref" | "psd" | "cmd"
  std::array<int, 3> owner{{-1, -1, -1}};       // sensor moving each axis: 0 table, 1 head
  // Decimated kinematics on the set-point's time (mm, mm/s, mm/s²) and the measurement.
  Eigen::MatrixXd cmd, v_cmd, a_cmd, x_meas, v_meas, a_meas;
  Eigen::MatrixXd temp_c;     // n × 2: case temperature minus its start, table, head
  Eigen::VectorXd t_s;        // time from the start of the motion
  std::vector<int> segment;   // per sample: which stretch between M102 marks
  std::vector<bool> heldout;  // per sample: held out of the fits (every other stretch or half second)
  // The integrated motion against each axis' reference, for the augmented filters
  // (kf_selection.hpp): where the reference is, at the standstills, the moves' starts.
  std::array<AxisTrack, 3> tracks;
  // Reference minus set-point where a reference is (what the ideal machine gets wrong):
  // white enough for plain weighted least squares.
  Channel machine;
  // The pipeline's path (ZUPT, smoother, no PSD fixes) minus each axis' reference: what
  // the report plots and the gain is measured on.
  Channel pipeline;
  Measurement measurement;  // nominal pipeline (keep_raw)
  RunMeta meta;
  double delay_samples = 38.8;  // what the pipeline removed
};

// Throws InputError when the run has no motion to explain.
RunResiduals build_residuals(const Run& run);

}  // namespace eical::dsp::model
