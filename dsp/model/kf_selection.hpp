#pragma once
// Forward selection of model extensions by generalised least squares through the
// integration's own noise model. The residual of an inertial path is no white noise: the
// sensors' noise, twice integrated, wanders by micrometres and more between supports, and
// any smooth regressor fits a wander. So each axis gets one augmented Kalman filter
// (identify/augmented_filter.hpp): the integration error [δx, δv, δb] with its noise and
// bias walk, plus the candidate parameters as constant states — acceleration-level ones
// drive δv, position-level ones enter the observation — observed where a reference says
// where the axis was, and at every standstill (ZUPT). The log-likelihood of the
// innovations scores a model exactly; BIC (with the effective count of the observations)
// with a held-out guard decides, as effect_selection.hpp does for white residuals.
#include "dsp/fusion/error_model.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace eical::dsp::model {

// One parameter on one axis: its input per sample (µm/s² per unit if `accel`, else µm per
// unit at the observations) and its prior σ.
struct AxisParam {
  std::string name;
  int axis = 0;
  bool accel = false;
  Eigen::VectorXd input;
  double prior_sigma = 1.0;
  double prior_mean = 0.0;  // what is known before the data (the Earth rate's Coriolis gain: 1)
};

struct ParamGroup {
  std::string name;
  std::vector<AxisParam> params;
  // Known from outside the run (the Earth rate): not selected by the BIC; tested once against
  // the final model and taken into it when the run shows it (known_min_loglik_gain).
  bool known = false;
};

struct AxisTrack {
  bool present = false;
  Eigen::VectorXd h_s;                  // step into each sample
  std::vector<std::uint8_t> bias_step;  // a move starts here (ch. 8.3.2)
  std::vector<std::uint8_t> zupt;       // the velocity is zero here
  Eigen::VectorXd v_um_s;               // the integrated velocity (ZUPT's observation)
  struct Obs {
    int sample = 0;
    double z_um = 0.0, sigma_um = 0.0;  // integrated position minus the reference
    bool heldout = false;
    int tag = -1;  // ≥ 0: an offset of its own (a PSD strip's mounting)
  };
  std::vector<Obs> obs;  // ascending sample
  int tags = 0;
  double start_bias_sigma_um_s2 = 0.0;  // how well the rest before the motion fixed the bias
};

struct GroupVerdict {
  std::string name;
  bool accepted = false;
  double bic_drop = 0.0;
  double fit_rms_before_um = 0.0, fit_rms_after_um = 0.0;    // innovations of the fitting observations
  double held_rms_before_um = 0.0, held_rms_after_um = 0.0;  // prediction errors at the held-out ones
  double held_score_gain = 0.0;  // gain in the held-out log predictive density (effective count)
  double loglik_gain = 0.0;      // 2 × log-likelihood gain in effective counts (the BIC drop without its penalty)
  std::map<std::string, double> value, sigma;
};

struct KfSelection {
  std::vector<GroupVerdict> groups;  // accepted first (in order), then the rest by BIC drop
  double fit_rms_nominal_um = 0.0, fit_rms_final_um = 0.0;
  double held_rms_nominal_um = 0.0, held_rms_final_um = 0.0;
  double held_expected_rms_final_um = 0.0;  // what the final model's noise lets it expect there
  // The same with every group of the table in the model at once: what no effect of the table
  // accounts for (sub-tolerance effects together included).
  double held_rms_all_um = 0.0, held_expected_rms_all_um = 0.0;
  double n_eff = 0.0;
  std::map<std::string, double> base_value, base_sigma;  // the base parameters in the final model
};

struct KfSelectionOptions {
  double min_bic_drop = 10.0;
  double min_heldout_gain = 0.02;
  double min_heldout_score_gain = 1.0;  // an e-fold better held-out prediction
  int max_groups = 8;
  double zupt_sigma_um_s = 2.0;
  // A known group (its size fixed by physics, not fitted freely) joins the final model when
  // the run favours it (2·Δlog L above this: "positive" evidence, Kass & Raftery) and it
  // predicts the held-out data no worse.
  double known_min_loglik_gain = 2.0;
};

// `base`: parameters every model carries (nuisances such as the servo lag of an axis seen
// against its set-point only); not selected, not counted in the BIC.
KfSelection select_groups_kf(const std::array<AxisTrack, 3>& tracks, const std::vector<ParamGroup>& groups,
                             const fusion::ErrorModel& model, const KfSelectionOptions& options = {},
                             const std::vector<AxisParam>& base = {});

}  // namespace eical::dsp::model
