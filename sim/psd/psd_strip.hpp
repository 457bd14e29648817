#pragma once
// A 1-D position-sensitive detector strip on the table, lit by the laser spot on the head
// (the embedded calibrator's support points, ch. 9.7). The spot (Gaussian, 1/e² diameter
// spot_mm) lights the strip with the fraction of its power that falls on the active area;
// the two electrodes share the photocurrent by the spot's position u along the strip,
// electrode 1 at the +u end (as in the sample runs of tests/data):
//   i1 = I·FS·(1/2 + u'/L),  i2 = I·FS·(1/2 − u'/L),  u' = u (1 + nl (2u/L)²).
// The lock-in amplifier's output follows with its first-order time constant.
#include "dsp/core/run_meta.hpp"
#include "sim/scenario.hpp"

#include <Eigen/Core>

namespace eical::sim {

class PsdStrip {
 public:
  PsdStrip(const dsp::PsdSpec& spec, const PsdTruth& truth, double step_s);
  // Lock-in outputs (V) for the relative position at this internal sample.
  void step(const Eigen::Vector3d& rel_mm, double& i1_v, double& i2_v) noexcept;

 private:
  dsp::PsdSpec spec_;
  PsdTruth truth_;
  int along_, across_;
  double sigma_mm_, alpha_;
  double i1_ = 0.0, i2_ = 0.0;
  double prev1_ = 0.0, prev2_ = 0.0, h_ = 1e-5;  // the inputs at the previous step
};

}  // namespace eical::sim
