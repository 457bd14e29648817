#include "dsp/fusion/error_covariance.hpp"

#include "dsp/core/error.hpp"
#include "dsp/fusion/rts_smoother.hpp"

#include <cmath>

namespace eical::dsp::fusion {

ErrorCovariance::ErrorCovariance(const SupportSchedule& schedule, const std::vector<std::int64_t>& sample_index,
                                 double fs_hz, ErrorModel model, const Vec3& start_bias_sigma_um_s2) {
  model.gate_nis = 1e300;         // the covariance of the supports as scheduled
  model.start_position_um = 0.0;  // measured from where it starts
  model.reset_after_rejections = 1 << 30;
  model.scale_state_ppm = {};  // the sensors' noise alone: the scale is no noise,
  model.timing_state_us = {};  // nor is the timing
  const std::size_t n = sample_index.size();
  SupportSchedule noise_only = schedule;  // the strips' own noise: the bound is the sensors'
  for (auto& f : noise_only.fixes) f.model_sigma_um = 0.0;
  // The smoother wants a trace; the covariance does not depend on it.
  const std::vector<Eigen::Vector3d> zero(n, Eigen::Vector3d::Zero());
  SmootherInput in;
  in.sample_index = &sample_index;
  in.vel_mm_s = &zero;
  in.pos_mm = &zero;
  in.schedule = &noise_only;
  in.fs_hz = fs_hz;
  in.model = model;
  in.start_bias_sigma_um_s2 = start_bias_sigma_um_s2;
  in.keep_gains = true;
  SmootherOutput out = smooth(in);
  for (int a = 0; a < 3; ++a) gain_[a] = std::move(out.gain[a]), p_[a] = std::move(out.p_smoothed[a]);
}

double ErrorCovariance::sigma_um(std::size_t k, int axis) const {
  return std::sqrt(std::max(0.0, p_[axis].at(k)(0, 0)));
}

Eigen::MatrixXd ErrorCovariance::position(const std::vector<std::size_t>& at, int axis) const {
  const auto m = static_cast<Eigen::Index>(at.size());
  Eigen::MatrixXd c(m, m);
  const auto& g = gain_[axis];
  const auto& p = p_[axis];
  // Chain of gains from each grid point to the next: T_i = C_{at_i} … C_{at_{i+1}−1}.
  std::vector<StateCov> t(at.size(), StateCov::Identity());
  for (std::size_t i = 0; i + 1 < at.size(); ++i) {
    if (at[i + 1] < at[i]) throw InputError("error covariance: positions must ascend");
    for (std::size_t k = at[i]; k < at[i + 1]; ++k) t[i] = t[i] * g[k];
  }
  for (Eigen::Index a = 0; a < m; ++a) {
    StateCov chain = StateCov::Identity();
    for (Eigen::Index b = a; b < m; ++b) {
      if (b > a) chain = chain * t[static_cast<std::size_t>(b - 1)];
      const double v = (chain * p[at[static_cast<std::size_t>(b)]])(0, 0);
      c(a, b) = c(b, a) = v;
    }
  }
  return c;
}

}  // namespace eical::dsp::fusion
