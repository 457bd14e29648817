#include "dsp/eval/positioning.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace eical::dsp::eval {
namespace {

// Hand-computed example: targets 0, 10, 20 mm, 3 runs.
//   up:   run1 [1 2 3], run2 [3 4 5], run3 [2 3 4]  → x̄↑ = [2 3 4], s↑ = [1 1 1]
//   down: run1 [0 0 1], run2 [0 2 1], run3 [0 1 1]  → x̄↓ = [0 1 1], s↓ = [0 1 0]
//   B_i = [2 2 3]: B = 3, B̄ = 7/3;  R_i↑ = 4, R_i↓ = [0 4 0];
//   R_i = max(2s↑ + 2s↓ + |B_i|, R↑, R↓) = [4 6 5]: R = 6, R↑ = 4, R↓ = 4
//   E↑ = 4 − 2 = 2, E↓ = 1 − 0 = 1, E = max(4, 1) − min(2, 0) = 4
//   x̄i = [1 2 2.5]: M = 1.5
//   A↑ = max[4 5 6] − min[0 1 2] = 6; A↓ = max[0 3 1] − min[0 −1 1] = 4; A = 6 − (−1) = 7
//   VDI 3441: U_i = [2 2 3] → U = 3; Ps_i = 6·(s↑ + s↓)/2 = [3 6 3] → Ps = 6; Pa = 1.5;
//   P = max(x̄i + (U_i + Ps_i)/2) − min(x̄i − (U_i + Ps_i)/2) = max[3.5 6 5.5] − min[−1.5 −2 −0.5] = 8
PositioningInput example() {
  PositioningInput in;
  in.targets_mm = {0, 10, 20};
  in.up_um = {{1, 2, 3}, {3, 4, 5}, {2, 3, 4}};
  in.down_um = {{0, 0, 1}, {0, 2, 1}, {0, 1, 1}};
  return in;
}

TEST(Positioning, HandComputedExample) {
  const auto r = evaluate_positioning(example());
  EXPECT_NEAR(r.B_um, 3.0, 1e-12);
  EXPECT_NEAR(r.B_mean_um, 7.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.R_um, 6.0, 1e-12);
  EXPECT_NEAR(r.R_up_um, 4.0, 1e-12);
  EXPECT_NEAR(r.R_down_um, 4.0, 1e-12);
  EXPECT_NEAR(r.E_up_um, 2.0, 1e-12);
  EXPECT_NEAR(r.E_down_um, 1.0, 1e-12);
  EXPECT_NEAR(r.E_um, 4.0, 1e-12);
  EXPECT_NEAR(r.M_um, 1.5, 1e-12);
  EXPECT_NEAR(r.A_up_um, 6.0, 1e-12);
  EXPECT_NEAR(r.A_down_um, 4.0, 1e-12);
  EXPECT_NEAR(r.A_um, 7.0, 1e-12);
  EXPECT_NEAR(r.vdi.U_um, 3.0, 1e-12);
  EXPECT_NEAR(r.vdi.Ps_um, 6.0, 1e-12);
  EXPECT_NEAR(r.vdi.Pa_um, 1.5, 1e-12);
  EXPECT_NEAR(r.vdi.P_um, 8.0, 1e-12);
  ASSERT_EQ(r.targets.size(), 3u);
  EXPECT_NEAR(r.targets[1].R_um, 6.0, 1e-12);
  EXPECT_NEAR(r.targets[2].mean_um, 2.5, 1e-12);
}

TEST(Positioning, BadInput) {
  auto in = example();
  in.up_um.resize(1);
  EXPECT_THROW((void)evaluate_positioning(in), InputError);
  in = example();
  in.down_um[1].pop_back();
  EXPECT_THROW((void)evaluate_positioning(in), InputError);
  in = example();
  in.up_um[2][1] = std::nan("");
  EXPECT_THROW((void)evaluate_positioning(in), InputError);
}

}  // namespace
}  // namespace eical::dsp::eval
