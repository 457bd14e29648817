#pragma once
// The effects of run-format.md's table as model extensions.
//
// Sensor side (sensor_groups): parameters per axis for the augmented filters of
// kf_selection.hpp — acceleration-level ones (scale, the cross-axis terms of mounting and
// non-orthogonal axes, nonlinearity, bias drift, temperature, Coriolis) drive the
// integration error, position-level ones (the timing 2ζ/ω0 or a delay shifts the path by,
// damping growing with |a|) enter where the path is observed.
// Machine side (machine_effects): where the machine really goes against its set-point —
// plain position-level columns (µm per unit), for least squares on reference − set-point
// and, split per axis, for the filters of axes that have only the set-point.
//
// Every effect also knows its tolerance band: what a data-sheet sensor or a well-kept
// machine shows anyway (background). A statistically significant fit inside its band is
// not something the model gets wrong that matters.
#include "dsp/model/kf_selection.hpp"
#include "dsp/model/run_residuals.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace eical::dsp::model {

// A machine effect's columns: per parameter, n × 3 (µm per unit).
struct EffectModel {
  std::string name;
  std::vector<std::string> params;
  std::vector<Eigen::MatrixXd> columns;
  std::function<double(const Eigen::VectorXd&)> magnitude;
  double tolerance = 0.0;
  std::string unit, regressor;
};

std::vector<ParamGroup> sensor_groups(const RunResiduals& run);

// The lag every axis' position loop has (feed-forward below 100 %) is part of the base
// model of reference − set-point, not an effect; what the axes differ by is. A P position
// loop with velocity feed-forward lags by e = (1 − ff)/kv · LP(v), LP a first-order lag of
// time constant 1/kv; a velocity loop behind it adds a term in LP(a). Columns (n × 3):
// −LP(v) in µm per ms of lag, LP(a) in µm per ms².
struct LagColumns {
  std::array<double, 3> tau_s{};  // per axis
  Eigen::MatrixXd velocity, acceleration;
};
LagColumns common_lag_columns(const RunResiduals& run, const std::array<double, 3>& tau_s_per_axis);
// Each axis loop's time constant: the value whose columns fit `hint` best (0: not moving).
std::array<double, 3> loop_time_constant_s(const RunResiduals& run, const Eigen::MatrixXd& hint);
// `hint` with each axis' offset and loop lag (these columns) fitted and taken out: what
// the effects' shapes are chosen on.
Eigen::MatrixXd without_lag(const Eigen::MatrixXd& hint, const LagColumns& lag);

// `hint` (n × 3, NaN where unknown): the residual that shows machine effects, to pick the
// reversal spike's time constant and the cyclic error's pitch; `lag` the base model's loop.
std::vector<EffectModel> machine_effects(const RunResiduals& run, const Eigen::MatrixXd& hint, const LagColumns& lag);

// The servo of each moving axis that has only its set-point as reference: its loop lag and
// acceleration term (the lag columns), for the base model of the augmented filters.
std::vector<AxisParam> servo_base(const RunResiduals& run, const LagColumns& lag);

// A machine effect as per-axis position-level parameters (for axes with the set-point only).
ParamGroup as_group(const EffectModel& e, const std::array<bool, 3>& axes);

// A named effect's size from fitted parameters (name → value) and its band.
// The sign of an axis' last commanded motion per sample (held through rests, 0 before the
// first) and the samples where it reverses.
void axis_directions(const RunResiduals& run, int axis, Eigen::VectorXd& dir, std::vector<int>& reversals);

struct Attribution {
  std::string name;
  double magnitude = 0.0, tolerance = 0.0;
  std::string unit, regressor;  // sizes beyond a kind's bound: effects.hpp, apply_physical_bounds
  std::map<std::string, double> params;
};
// The named effects a sensor group's fit stands for (the cross-axis group splits into
// mounting rotation and non-orthogonality, the timing group into the sensors' own timing
// and — against the set-point only — the axes' servo mismatch).
std::vector<Attribution> attribute_sensor_group(const RunResiduals& run, const std::string& group,
                                                const std::map<std::string, double>& values);

}  // namespace eical::dsp::model
