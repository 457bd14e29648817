// The fusion layer against independent formulations: the discrete noise against numerical
// integration of the continuous model, the scalar update against the textbook Kalman
// update, and the RTS smoother against the batch posterior of the whole trajectory
// (Gaussian conditioning of the stacked states) — they must agree to rounding.
#include "dsp/fusion/axis_filter.hpp"
#include "dsp/fusion/checkpointed_smoother.hpp"
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/rts_smoother.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

namespace eical::dsp::fusion {
namespace {

TEST(ErrorModel, DiscreteNoiseEqualsTheIntegralOfTheContinuousModel) {
  ErrorModel m;
  m.accel_noise_um_s2_rthz = 3.0;
  m.bias_walk_um_s2_rts = 7.0;
  const double h = 0.01;
  // Q = ∫0^h e^{As} G Qc Gᵀ e^{Aᵀs} ds, A = [0 1 0; 0 0 1; 0 0 0], noise into δv and δb.
  Mat3 qc = Mat3::Zero();
  qc(1, 1) = 9.0, qc(2, 2) = 49.0;
  Mat3 q = Mat3::Zero();
  const int steps = 20000;
  for (int i = 0; i < steps; ++i) {
    const double s = (i + 0.5) * h / steps;
    Mat3 phi;
    phi << 1, s, s * s / 2, 0, 1, s, 0, 0, 1;
    q += phi * qc * phi.transpose() * (h / steps);
  }
  const Discrete d = discretise(m, h);
  EXPECT_LT((d.Q.topLeftCorner<3, 3>() - q).cwiseAbs().maxCoeff() / q.cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_DOUBLE_EQ(d.F(0, 2), h * h / 2);
  // The scale is constant: no flow into or out of it, no noise.
  EXPECT_EQ(d.F.row(kScaleState), StateRow::Unit(kScaleState));
  EXPECT_EQ(d.F.col(kScaleState), State::Unit(kScaleState));
  EXPECT_EQ(d.Q.row(kScaleState).norm(), 0.0);
}

TEST(AxisFilter, ScalarUpdateEqualsTheGeneralKalmanUpdate) {
  AxisFilter f;
  f.e << 1.0, -2.0, 0.5, 40.0, 1.5;
  StateCov a = StateCov::Random();
  f.P = a * a.transpose() + StateCov::Identity();
  const State e0 = f.e;
  const StateCov p0 = f.P;
  const double z = 0.3, r = 0.7;
  const UpdateRecord rec = f.update(1, z, r, 1e9);
  const StateRow h = StateRow::Unit(1);
  const double s = (h * p0 * h.transpose())(0) + r;
  const State k = p0 * h.transpose() / s;
  EXPECT_LT((f.e - (e0 + k * (z - h * e0))).norm(), 1e-12);
  EXPECT_LT((f.P - (StateCov::Identity() - k * h) * p0).norm(), 1e-12);
  EXPECT_TRUE(rec.accepted);
  EXPECT_NEAR(rec.nis, (z - e0[1]) * (z - e0[1]) / s, 1e-12);
}

TEST(AxisFilter, GateRejectsAnOutlierAndLeavesTheStateAlone) {
  AxisFilter f;
  f.P = StateCov::Identity();
  const UpdateRecord rec = f.update(0, 100.0, 1.0, 25.0);
  EXPECT_FALSE(rec.accepted);
  EXPECT_EQ(f.e, State::Zero());
  EXPECT_EQ(f.P, StateCov::Identity());
  EXPECT_FALSE(f.update(0, std::nan(""), 1.0, 25.0).accepted);  // NaN never enters
}

// The batch posterior of the stacked trajectory X = [e_0 … e_{n−1}] given every
// observation, by Gaussian conditioning: E[X|Z] = Σ Hᵀ (H Σ Hᵀ + R)⁻¹ Z.
struct Batch {
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
};

Batch batch_posterior(const ErrorModel& m, double h, const Vec3& bias0, const SupportSchedule& sch,
                      const std::vector<Eigen::Vector3d>& vel, const std::vector<Eigen::Vector3d>& pos, int axis) {
  constexpr Eigen::Index ns = kStates;
  const auto n = static_cast<Eigen::Index>(sch.flags.size());
  const Discrete d = discretise(m, h);
  std::vector<StateCov> p(static_cast<std::size_t>(n));
  p[0] = initial_covariance(m, axis, bias0[axis]);
  for (Eigen::Index k = 1; k < n; ++k) {
    p[static_cast<std::size_t>(k)] = d.F * p[static_cast<std::size_t>(k - 1)] * d.F.transpose() + d.Q;
    if (sch.flags[static_cast<std::size_t>(k)] & schedule_flag::move_start)
      p[static_cast<std::size_t>(k)](2, 2) += m.bias_step_um_s2 * m.bias_step_um_s2;
  }
  Eigen::MatrixXd sigma(ns * n, ns * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    StateCov fpow = StateCov::Identity();
    for (Eigen::Index j = i; j < n; ++j) {
      const StateCov c = fpow * p[static_cast<std::size_t>(i)];  // Cov(x_j, x_i)
      sigma.block<ns, ns>(ns * j, ns * i) = c;
      sigma.block<ns, ns>(ns * i, ns * j) = c.transpose();
      fpow = d.F * fpow;
    }
  }
  // Each observation as a row over the stacked trajectory: a velocity reads δv; a position
  // δx and, where the scale is a state, δs times the way (support_rows.hpp).
  const bool scale = m.scale_state_ppm[static_cast<std::size_t>(axis)] > 0.0;
  std::vector<Eigen::RowVectorXd> rows;
  std::vector<double> z, r;
  const auto unit = [&](Eigen::Index i) { return Eigen::RowVectorXd::Unit(ns * n, i); };
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto f = sch.flags[static_cast<std::size_t>(k)];
    if (f & schedule_flag::rest)
      rows.push_back(unit(ns * k + 1)), z.push_back(vel[static_cast<std::size_t>(k)][axis] * 1000),
          r.push_back(m.zupt_sigma_um_s * m.zupt_sigma_um_s);
    else if (f & nbs_flag(axis))
      rows.push_back(unit(ns * k + 1)), z.push_back(vel[static_cast<std::size_t>(k)][axis] * 1000),
          r.push_back(m.nbs_sigma_um_s * m.nbs_sigma_um_s);
    for (const auto& fx : sch.fixes)
      if (static_cast<Eigen::Index>(fx.k) == k && fx.axis == axis) {
        Eigen::RowVectorXd row = unit(ns * k);
        if (scale) row[ns * k + kScaleState] = 1e-3 * fx.way_mm;
        rows.push_back(row), z.push_back(pos[fx.k][axis] * 1000 - fx.position_um),
            r.push_back(fx.sigma_um * fx.sigma_um + m.psd_floor_um * m.psd_floor_um);
      }
  }
  const auto nz = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd hs(nz, ns * n);  // H Σ
  Eigen::MatrixXd s(nz, nz);
  Eigen::VectorXd zv(nz);
  for (Eigen::Index i = 0; i < nz; ++i) {
    hs.row(i) = rows[static_cast<std::size_t>(i)] * sigma;
    zv[i] = z[static_cast<std::size_t>(i)];
  }
  for (Eigen::Index i = 0; i < nz; ++i)
    for (Eigen::Index j = 0; j < nz; ++j)
      s(i, j) = hs.row(i).dot(rows[static_cast<std::size_t>(j)]) + (i == j ? r[static_cast<std::size_t>(i)] : 0.0);
  const Eigen::LDLT<Eigen::MatrixXd> ls(s);
  Batch b;
  b.mean = hs.transpose() * ls.solve(zv);
  b.cov = sigma - hs.transpose() * ls.solve(hs);
  return b;
}

// With the scale a state on x (strips 80 mm apart observe it), the position the smoother
// reports adds δs·way and its σ the scale's share: the same batch posterior gives both.
TEST(RtsSmoother, EqualsTheBatchPosteriorOfTheWholeTrajectory) {
  for (const bool scale : {false, true}) {
    ErrorModel m;
    m.gate_nis = 1e12;  // compare the algebra, not the gate
    m.bias_walk_um_s2_rts = 30.0;
    if (scale) m.scale_state_ppm = {300.0, 0.0, 0.0};
    const double fs = 1000.0;
    const std::size_t n = 60;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0.0, 1.0);
    SupportSchedule sch;
    sch.flags.assign(n, 0);
    for (std::size_t k = 0; k < 8; ++k) sch.flags[k] = schedule_flag::rest;
    sch.flags[8] |= schedule_flag::move_start;
    for (std::size_t k = 20; k < 30; ++k) sch.flags[k] = nbs_flag(1);
    for (std::size_t k = 50; k < n; ++k) sch.flags[k] = schedule_flag::rest;
    const double way_mm_per_sample = 2.0;  // x's way: linear, so its velocity is exact at every sample
    if (scale)
      for (std::size_t k = 0; k < n; ++k)
        sch.way_mm.emplace_back(static_cast<float>(way_mm_per_sample * static_cast<double>(k)), 0.0F, 0.0F);
    for (std::size_t k : {15u, 16u, 17u, 40u}) {
      sch.fixes.push_back({k, 0, g(rng) * 5.0, 0.3});
      sch.fixes.back().way_mm = way_mm_per_sample * static_cast<double>(k);
    }
    sch.fixes.push_back({33, 1, g(rng) * 5.0, 0.5});
    std::vector<Eigen::Vector3d> vel(n), pos(n);
    std::vector<std::int64_t> idx(n);
    for (std::size_t k = 0; k < n; ++k) {
      vel[k] = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 0.01;
      pos[k] = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 0.01;
      idx[k] = static_cast<std::int64_t>(k);
    }
    SmootherInput in;
    in.sample_index = &idx, in.vel_mm_s = &vel, in.pos_mm = &pos, in.schedule = &sch, in.fs_hz = fs, in.model = m;
    in.start_bias_sigma_um_s2 = Vec3(5.0, 8.0, 3.0);
    in.keep_gains = true;
    const SmootherOutput out = smooth(in);
    for (int a = 0; a < 2; ++a) {
      const Batch b = batch_posterior(m, 1.0 / fs, in.start_bias_sigma_um_s2, sch, vel, pos, a);
      const bool scaled = scale && a == 0;
      for (std::size_t k = 0; k < n; ++k) {
        const auto i = static_cast<Eigen::Index>(kStates * k), j = i + kScaleState;
        const double w = scaled ? 1e-3 * way_mm_per_sample * static_cast<double>(k) : 0.0;
        const double v = scaled ? 1e-3 * way_mm_per_sample * fs : 0.0;
        const double x = b.mean[i] + w * b.mean[j], dv = b.mean[i + 1] + v * b.mean[j];
        const double var = b.cov(i, i) + 2.0 * w * b.cov(i, j) + w * w * b.cov(j, j);
        EXPECT_NEAR(out.dx_um[k][a], x, 1e-7 * (1.0 + std::abs(x))) << "axis " << a << " sample " << k;
        EXPECT_NEAR(out.dv_um_s[k][a], dv, 1e-6 * (1.0 + std::abs(dv)));
        EXPECT_NEAR(out.sigma_x_um[k][a], std::sqrt(var), 1e-7 * (1.0 + std::sqrt(var)));
      }
      if (scaled) {  // the strips saw the scale
        EXPECT_LT(std::sqrt(b.cov(kScaleState, kScaleState)), 300.0);
      }
      // Cross-time covariance from the gains: Cov(x_j, x_k | all) = C_j … C_{k−1} P_k|N.
      StateCov chain = out.p_smoothed[a][45];
      for (std::size_t j = 45; j-- > 35;) chain = out.gain[a][j] * chain;
      const double c = b.cov(kStates * 35, kStates * 45);
      EXPECT_NEAR(chain(0, 0), c, 1e-7 * (1.0 + std::abs(c)));
    }
    EXPECT_EQ(out.tally[0][static_cast<int>(Support::cupt)].accepted, 4u);
    EXPECT_EQ(out.tally[1][static_cast<int>(Support::nbs)].accepted, 10u);
    EXPECT_EQ(out.tally[2][static_cast<int>(Support::zupt)].accepted, 18u);
  }
}

TEST(RtsSmoother, ForwardOnlyIsTheCausalFilterAndNeverBetterThanTheSmoother) {
  ErrorModel m;
  const std::size_t n = 400;
  SupportSchedule sch;
  sch.flags.assign(n, 0);
  for (std::size_t k = 350; k < n; ++k) sch.flags[k] = schedule_flag::rest;
  std::vector<Eigen::Vector3d> vel(n, Eigen::Vector3d::Constant(0.002)), pos(n, Eigen::Vector3d::Zero());
  std::vector<std::int64_t> idx(n);
  for (std::size_t k = 0; k < n; ++k) idx[k] = static_cast<std::int64_t>(k);
  SmootherInput in;
  in.sample_index = &idx, in.vel_mm_s = &vel, in.pos_mm = &pos, in.schedule = &sch, in.fs_hz = 1000.0, in.model = m;
  const SmootherOutput s = smooth(in);
  in.forward_only = true;
  const SmootherOutput f = smooth(in);
  EXPECT_EQ(f.dx_um[100][0], 0.0);  // before the first standstill the filter knows nothing yet
  EXPECT_NE(s.dx_um[100][0], 0.0);  // the smoother carries the standstill's news back
  for (std::size_t k = 0; k < n; ++k) EXPECT_LE(s.sigma_x_um[k][0], f.sigma_x_um[k][0] + 1e-12);
}

// The checkpointed smoother recomputes each segment from its checkpoint: however the
// measurement is split, every output is the same number (to the bit), across lost frames,
// covariance resets, window means and fixes on the segment boundaries.
TEST(CheckpointedSmoother, TheSplitIntoSegmentsChangesNoBit) {
  ErrorModel m;
  m.reset_after_rejections = 3;  // resets happen (a standstill the model does not expect)
  const std::size_t n = 500;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  SupportSchedule sch;
  sch.flags.assign(n, 0);
  sch.zupt_sigma_um_s.assign(n, 0.0F);
  for (std::size_t k = 0; k < 40; ++k) sch.flags[k] = schedule_flag::rest;
  sch.flags[40] |= schedule_flag::move_start;
  for (std::size_t k = 100; k < 180; ++k) sch.flags[k] = nbs_flag(2);
  for (std::size_t k = 250; k < 330; ++k)
    sch.flags[k] = schedule_flag::rest, sch.zupt_sigma_um_s[k] = k < 280 ? -1.0F : 0.0F;
  sch.flags[260] |= schedule_flag::invalid;
  for (std::size_t k = 450; k < n; ++k) sch.flags[k] = schedule_flag::rest;
  for (std::size_t k : {63u, 64u, 128u, 255u, 256u, 400u})
    sch.fixes.push_back({k, static_cast<int>(k % 3), g(rng) * 5.0, 0.3});
  sch.velocity_means.push_back({264, {1.0, -2.0, 0.5}, 3.0, 0.01});
  sch.velocity_means.push_back({256, {0.5, 0.2, -0.1}, 3.0, 0.01});
  std::vector<Eigen::Vector3d> vel(n), pos(n);
  std::vector<std::int64_t> idx(n);
  std::int64_t t = 0;
  for (std::size_t k = 0; k < n; ++k) {
    vel[k] = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 0.05 +
             Eigen::Vector3d::Constant(k > 450 ? 0.2 : 0.0);  // a bias jump at the end
    pos[k] = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 0.01;
    t += (k == 64 || k == 300) ? 3 : 1;  // lost frames, one on a boundary of the 64-sample split
    idx[k] = t;
  }
  const SmootherTrack track = smoother_track(idx, vel, pos, sch);
  for (const bool forward_only : {false, true}) {
    SmootherSettings st;
    st.fs_hz = 1000.0, st.model = m, st.forward_only = forward_only;
    const CheckpointedSmoother whole(track, st, n);
    ASSERT_EQ(whole.segments(), 1u);
    SmoothedSegment ref;
    whole.segment(0, ref, true);
    EXPECT_GT(whole.resets(), 0u);
    // The backward pass' tasks (two axes; the third with the next refilter) in reverse
    // order: any executor may run them so.
    SmootherSettings reversed = st;
    reversed.parallel = [](std::size_t count, const ParallelTask& task) {
      for (std::size_t i = count; i-- > 0;) task(i);
    };
    for (const std::size_t split : {1u, 7u, 64u, 256u}) {
      const CheckpointedSmoother parts(track, split % 2 == 0 ? reversed : st, split);
      EXPECT_EQ(parts.resets(), whole.resets());
      EXPECT_EQ(parts.finite(), whole.finite());
      for (int a = 0; a < 3; ++a)
        for (int s = 0; s < kSupportKinds; ++s) EXPECT_EQ(parts.tally()[a][s].accepted, whole.tally()[a][s].accepted);
      SmoothedSegment seg;
      for (std::size_t j = parts.segments(); j-- > 0;) {  // any order
        parts.segment(j, seg, true);
        for (std::size_t i = 0; i < seg.size(); ++i) {
          const std::size_t k = seg.first + i;
          ASSERT_EQ(seg.dx_um[i], ref.dx_um[k]) << "split " << split << " sample " << k;
          ASSERT_EQ(seg.dv_um_s[i], ref.dv_um_s[k]);
          ASSERT_EQ(seg.sigma_x_um[i], ref.sigma_x_um[k]);
          for (int a = 0; a < 3; ++a) ASSERT_EQ(seg.gain[a][i], ref.gain[a][k]) << "split " << split << " sample " << k;
        }
      }
    }
  }
}

TEST(RtsSmoother, MismatchedLengthsAreAnError) {
  SupportSchedule sch;
  sch.flags.assign(3, 0);
  std::vector<Eigen::Vector3d> v(2);
  std::vector<std::int64_t> idx(3);
  SmootherInput in;
  in.sample_index = &idx, in.vel_mm_s = &v, in.pos_mm = &v, in.schedule = &sch;
  EXPECT_THROW((void)smooth(in), std::exception);
}

}  // namespace
}  // namespace eical::dsp::fusion
