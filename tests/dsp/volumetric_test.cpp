// The PTB acceptance test of seed 004, reproduced: three fictitious machines (axes
// < 2000 mm, tool offsets < 450 mm), 138 points, each deviation compared with an
// independent formulation to < 1 nm, and every range violation caught.
#include "dsp/comp/volumetric.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace eical::dsp::comp {
namespace {

VolumetricModel machine(std::uint64_t seed, const Eigen::Vector3d& travel) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> t_um(-15.0, 15.0), r_urad(-60.0, 60.0), w(-40.0, 40.0);
  VolumetricModel m;
  for (int a = 0; a < 3; ++a) m.range_mm[a] = {-0.1 * travel[a], 0.9 * travel[a]};
  m.xwy_urad = w(rng), m.xwz_urad = w(rng), m.ywz_urad = w(rng);
  for (int k = 0; k < 18; ++k) {
    const int a = k / 6;
    const bool rot = (k % 6) >= 3;
    const int n = 5 + static_cast<int>(rng() % 30);
    for (int i = 0; i <= n; ++i) {
      m.component[k].pos_mm.push_back(m.range_mm[a][0] + (m.range_mm[a][1] - m.range_mm[a][0]) * i / n);
      m.component[k].values.push_back(rot ? r_urad(rng) : t_um(rng));
    }
  }
  return m;
}

// Independent formulation: the machine as a chain of rigid bodies X → Y → Z → tool, each
// carried by the previous one: p = t_X + R_X (t_Y + R_Y (t_Z + R_Z x_P)), with small
// rotations R = I + [ω]× and the squareness tilting the Y and Z directions. It is reduced
// to first order by superposition: the chain is evaluated with one error parameter at a
// time (exactly linear in it) and the changes are summed — the model's own assumption
// that the error motions do not interact.
Eigen::Vector3d chain(const Eigen::Vector3d& x, const Eigen::Vector3d& xp, const std::array<double, 18>& c, double xwy,
                      double xwz, double ywz) {
  auto skew = [](double a, double b, double g) {
    Eigen::Matrix3d s;
    s << 0, -g, b, g, 0, -a, -b, a, 0;
    return s;
  };
  const double k = 1e-6, um = 1e-3;  // µrad → rad, µm → mm
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d RX = I + skew(c[3] * k, c[4] * k, c[5] * k);
  const Eigen::Matrix3d RY = I + skew(c[9] * k, c[10] * k, c[11] * k);
  const Eigen::Matrix3d RZ = I + skew(c[15] * k, c[16] * k, c[17] * k);
  const Eigen::Vector3d tX(x[0] + c[0] * um, c[1] * um, c[2] * um);
  const Eigen::Vector3d tY(-xwy * k * x[1] + c[6] * um, x[1] + c[7] * um, c[8] * um);
  const Eigen::Vector3d tZ(xwz * k * x[2] + c[12] * um, -ywz * k * x[2] + c[13] * um, x[2] + c[14] * um);
  return tX + RX * (tY + RY * (tZ + RZ * xp));
}

Eigen::Vector3d independent_um(const VolumetricModel& m, const Eigen::Vector3d& x, const Eigen::Vector3d& xp) {
  const auto c = component_values(m, x);
  const std::array<double, 18> zero{};
  const Eigen::Vector3d p0 = chain(x, xp, zero, 0, 0, 0);
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  for (int k = 0; k < 18; ++k) {
    std::array<double, 18> one{};
    one[k] = c[k];
    e += chain(x, xp, one, 0, 0, 0) - p0;
  }
  e += chain(x, xp, zero, m.xwy_urad, 0, 0) - p0;
  e += chain(x, xp, zero, 0, m.xwz_urad, 0) - p0;
  e += chain(x, xp, zero, 0, 0, m.ywz_urad) - p0;
  return e * 1000.0;
}

TEST(Volumetric, AgreesWithAnIndependentFormulationBelowOneNanometre) {
  const std::array<Eigen::Vector3d, 3> travels = {Eigen::Vector3d(1999, 1200, 800), Eigen::Vector3d(600, 600, 400),
                                                  Eigen::Vector3d(1500, 1999, 1000)};
  std::mt19937_64 rng(9);
  int points = 0, flagged = 0, violations = 0;
  double worst_nm = 0.0;
  for (int mi = 0; mi < 3; ++mi) {
    const VolumetricModel m = machine(100 + mi, travels[mi]);
    ASSERT_NO_THROW(validate(m));
    std::uniform_real_distribution<double> tool(-449.0, 449.0);
    for (int p = 0; p < 46; ++p, ++points) {
      Eigen::Vector3d x;
      int outside = -1;
      for (int a = 0; a < 3; ++a) {
        const double lo = m.range_mm[a][0], hi = m.range_mm[a][1];
        std::uniform_real_distribution<double> u(lo, hi);
        x[a] = u(rng);
      }
      if (p % 7 == 3) {  // every 7th point leaves one axis' range, below or above
        outside = p % 3;
        x[outside] = (p % 2) ? m.range_mm[outside][1] + 0.001 : m.range_mm[outside][0] - 5.0;
        ++violations;
      }
      if (p == 0) x = Eigen::Vector3d(m.range_mm[0][1], m.range_mm[1][0], m.range_mm[2][1]);  // range ends are inside
      const Eigen::Vector3d xp(tool(rng), tool(rng), tool(rng));
      const auto r = volumetric_deviation(m, x, xp);
      if (outside >= 0) {
        EXPECT_EQ(r.out_of_range_axis, outside) << "machine " << mi << " point " << p;
        flagged += r.out_of_range_axis == outside;
        continue;
      }
      ASSERT_TRUE(r.ok()) << "machine " << mi << " point " << p;
      const double d_nm = (r.e_um - independent_um(m, x, xp)).norm() * 1000.0;
      worst_nm = std::max(worst_nm, d_nm);
    }
  }
  std::printf(
      "volumetric: %d points, max deviation from the independent formulation %.2e nm, %d/%d range violations flagged\n",
      points, worst_nm, flagged, violations);
  EXPECT_EQ(points, 138);
  EXPECT_LT(worst_nm, 1.0);
  EXPECT_EQ(flagged, violations);
  EXPECT_GT(violations, 10);
}

TEST(Volumetric, SingleComponentsGiveTheTextbookLeverArms) {
  VolumetricModel m = machine(1, {1000, 1000, 1000});
  for (auto& c : m.component) std::fill(c.values.begin(), c.values.end(), 0.0);
  m.xwy_urad = m.xwz_urad = m.ywz_urad = 0.0;
  std::fill(m.component[4].values.begin(), m.component[4].values.end(), 10.0);  // xry = 10 µrad (pitch of X)
  const auto r = volumetric_deviation(m, {100, 200, 300}, {0, 0, 150});
  // Pitch of the X carriage tilts everything above it: Δx = xry·(z + zp) = 10 µrad · 450 mm.
  EXPECT_NEAR(r.e_um.x(), 4.5, 1e-12);
  EXPECT_NEAR(r.e_um.z(), 0.0, 1e-12);
}

TEST(Volumetric, BadModelsAreRefused) {
  VolumetricModel m = machine(2, {500, 500, 500});
  m.component[7].pos_mm.clear(), m.component[7].values.clear();
  EXPECT_THROW(validate(m), InputError);
  m = machine(2, {500, 500, 500});
  m.component[0].pos_mm[2] = m.component[0].pos_mm[1];
  EXPECT_THROW(validate(m), InputError);
  m = machine(2, {500, 500, 500});
  m.component[15].pos_mm.back() -= 10.0;  // does not cover the range
  EXPECT_THROW(validate(m), InputError);
}

}  // namespace
}  // namespace eical::dsp::comp
