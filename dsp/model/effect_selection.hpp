#pragma once
// Which model extensions does the data support? Forward selection over candidate effects,
// each a block of regressors that is linear in its parameters (or linearised about the
// nominal model), scored by the Bayesian information criterion with an effective sample
// count, and guarded against fitting noise by held-out data.
//
//   BIC = n_eff · ln(RSS/n) + p · ln(n_eff)
//
// n_eff = n / τ_int with τ_int the integrated autocorrelation time of the residual
// (samples at 10 kHz are far from independent; counting them all would make every wiggle
// "significant"). An effect is accepted when its BIC drop exceeds `min_bic_drop` (10 =
// "very strong" evidence on the Kass–Raftery scale) AND it lowers the held-out RMS by at
// least `min_heldout_gain` (a relative fraction). Each accepted effect enters the model
// before the next is tested, so correlated candidates do not claim the same residual twice.
#include <Eigen/Core>

#include <string>
#include <vector>

namespace eical::dsp::model {

struct Candidate {
  std::string name;                      // effect name from run-format.md, or other.<name>
  Eigen::MatrixXd regressors;            // n × k: residual ≈ regressors · params
  std::vector<std::string> param_names;  // k names
};

struct SelectionOptions {
  double min_bic_drop = 10.0;
  // Per sample: the block it belongs to for the jackknife standard errors (empty: none).
  // The residual of a model fitted to data it does not describe exactly is correlated in
  // ways a white-noise formula misses; leaving out one block at a time shows how much a
  // parameter depends on any one stretch of the run.
  std::vector<int> block;
  double min_heldout_gain = 0.02;  // 2 % lower held-out RMS
  int max_effects = 8;
};

struct EffectVerdict {
  std::string name;
  bool significant = false;
  double bic_drop = 0.0;                                     // when tested (against the model accepted so far)
  double rms_before = 0.0, rms_after = 0.0;                  // fitting samples
  double heldout_rms_before = 0.0, heldout_rms_after = 0.0;  // held-out samples
  double correlation = 0.0;  // |corr| of the residual with the block's best single regressor
  std::vector<std::string> param_names;
  Eigen::VectorXd params;  // fitted with the accepted model (all samples of the fitting set)
  Eigen::VectorXd
      param_sigma;  // their standard errors: the larger of residual variance per effective sample and block jackknife
};

struct SelectionResult {
  std::vector<EffectVerdict> effects;  // every candidate; significant ones first, in order of acceptance
  double rms_nominal = 0.0, rms_final = 0.0;
  double heldout_rms_nominal = 0.0, heldout_rms_final = 0.0;
  double n_eff = 0.0;              // effective independent samples of the fitting set
  Eigen::VectorXd final_residual;  // all samples, after the accepted effects
};

// `heldout[i]` true marks a sample used only for checking. Throws InputError when sizes
// disagree, values are non-finite or either set is empty.
SelectionResult select_effects(const Eigen::VectorXd& residual, const std::vector<Candidate>& candidates,
                               const std::vector<bool>& heldout, const SelectionOptions& options = {});

// Integrated autocorrelation time in samples (1 = white), summed until the first
// non-positive autocorrelation.
double integrated_autocorrelation_time(const Eigen::VectorXd& x, int max_lag = 20000);

}  // namespace eical::dsp::model
