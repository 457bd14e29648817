#pragma once
// How far the bias jumps from one standstill to the next, measured on the run itself.
//
// The error model lets the bias jump at every start of a move (ch. 8.3.2: each partial
// move has its own offset; ErrorModel::bias_step_um_s2). The thesis measured about 2 µg on
// its sensors; another sensor, or a machine whose tilt changes the gravity's share along
// the way, has its own. Every standstill shows the bias there: the mean relative reading
// over its late part (the settling over). Between two standstills that mean changes by
//
//   d = step + walk + noise,   E[d²] = σ_step² + q_b·Δt + q_a/T₁ + q_a/T₂
//
// (q_a: the reading's white-noise density², measured from the scatter of the standstills'
// batch means; q_b: the bias walk², data sheet; T: the late parts' lengths). The first
// standstill is compared with the rest before the motion, whose mean is the bias removed
// (its σ measured there). σ_step² is what is left of Σ(d² − the rest) over every pair and
// axis, plus one standard error of that sum: the step the standstills cannot rule out.
// Only neighbours at most 5 s apart count (further apart a drift dominates, the case
// warming, which is no jump per move), and at least 3 such pairs.
#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace eical::dsp::fusion {

// One standstill's late part: when (from the start of the motion), how long, its mean.
struct StandstillMean {
  double t_s = 0.0;
  double length_s = 0.0;
  Eigen::Vector3d mean_um_s2 = Eigen::Vector3d::Zero();  // relative reading after the start bias
};

struct BiasStepMeasurement {
  bool measured = false;     // enough pairs: otherwise keep the model's
  double step_um_s2 = 0.0;   // σ of the jump at a move start (upper one-σ bound)
  double excess_um2_s4 = 0;  // Σ(d² − expected) / (3·pairs): the point estimate of σ_step² (may be < 0)
  std::size_t pairs = 0;
  double noise_um_s2_rthz = 0.0;  // √q_a as the standstills' batch means show it
};

// batch_var_um2_s4: the pooled variance of batch means (each batch_s long) about their
// standstill's mean, with its degrees of freedom; below 5 the model's noise density
// (model_noise_um_s2_rthz) stands in.
BiasStepMeasurement measure_bias_step(const std::vector<StandstillMean>& standstills,
                                      const Eigen::Vector3d& start_bias_sigma_um_s2, double batch_var_um2_s4,
                                      std::size_t batch_dof, double batch_s, double model_noise_um_s2_rthz,
                                      double walk_um_s2_rts);

}  // namespace eical::dsp::fusion
