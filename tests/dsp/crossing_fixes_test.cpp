// One position per crossing where the readings' slope is the scale error (fusion/crossing_fixes).
#include "dsp/fusion/crossing_fixes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace eical::dsp::fusion {
namespace {

// A strip measuring x at `centre_mm` crossed from `from_mm` to `to_mm` in `n` samples from
// sample k0; the integrated position is the truth × (1 + scale) plus `offset_um`.
void cross(std::vector<PositionFix>& fixes, std::vector<double>& pos_mm, int strip, std::size_t k0, std::size_t n,
           double from_mm, double to_mm, double scale, double offset_um) {
  for (std::size_t i = 0; i < n; ++i) {
    const double x_mm = from_mm + (to_mm - from_mm) * static_cast<double>(i) / static_cast<double>(n - 1);
    fixes.push_back({k0 + i, 0, x_mm * 1000.0, 0.25, strip, 0.0});
    pos_mm.push_back(x_mm * (1.0 + scale) + offset_um / 1000.0);
  }
}

TEST(CrossingFixes, ACrossingAlongTheStripBecomesItsMeanInnovationAtItsMiddle) {
  std::vector<PositionFix> fixes;
  std::vector<double> pos_mm;
  cross(fixes, pos_mm, 0, 1000, 2001, 10.0, 20.0, 5e-4, 3.0);  // 5 µm of scale across 10 mm
  merge_crossings(fixes, pos_mm, 3e-4, 20);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].k, 2000u);  // the middle reading, at 15 mm
  // Integrated 15 mm × (1 + 5e-4) + 3 µm; the readings say 15 mm: the innovation is the
  // offset plus the scale's mean share (7.5 µm at the middle), 10.5 µm below.
  EXPECT_NEAR(fixes[0].position_um - pos_mm[0] * 1000.0, -10.5, 1e-6);
  EXPECT_NEAR(fixes[0].sigma_um, 0.25 / std::sqrt(2001.0), 1e-9);
}

TEST(CrossingFixes, ReadingsThatResolveNoSlopeBeyondTheScaleStayAsTheyAre) {
  std::vector<PositionFix> fixes;
  std::vector<double> pos_mm;
  // A radial strip: the spot crosses its width while x barely moves (2 µm).
  cross(fixes, pos_mm, 0, 0, 80, 50.000, 50.002, 0.0, 0.0);
  merge_crossings(fixes, pos_mm, 3e-4, 20);
  EXPECT_EQ(fixes.size(), 80u);
}

TEST(CrossingFixes, StripsReadAtOnceAreCrossingsOfTheirOwnAndTheSamePlaceAddsNoScale) {
  std::vector<PositionFix> a, b;
  std::vector<double> pa, pb;
  cross(a, pa, 0, 0, 500, 10.0, 20.0, 5e-4, 0.0);
  cross(b, pb, 1, 0, 500, 40.0, 50.0, 5e-4, 0.0);
  std::vector<PositionFix> fixes;
  std::vector<double> pos_mm;
  for (std::size_t i = 0; i < a.size(); ++i)  // interleaved, as two lit strips are recorded
    fixes.push_back(a[i]), pos_mm.push_back(pa[i]), fixes.push_back(b[i]), pos_mm.push_back(pb[i]);
  cross(fixes, pos_mm, 0, 5000, 500, 20.0, 10.0, 5e-4, 0.0);  // strip 0 again, the other way
  for (auto& f : fixes) f.model_sigma_um = 9.0;
  merge_crossings(fixes, pos_mm, 3e-4, 20);
  ASSERT_EQ(fixes.size(), 3u);
  EXPECT_EQ(fixes[0].strip == fixes[1].strip, false);
  EXPECT_LE(fixes[0].k, fixes[1].k);
  EXPECT_LE(fixes[1].k, fixes[2].k);
  EXPECT_EQ(fixes[2].strip, 0);
  // The first crossing keeps its distance from the start; strip 1 follows strip 0 on the
  // same axis 30 mm away (9 µm of scale at 3e-4); strip 0 again is where strip 1 was last.
  EXPECT_DOUBLE_EQ(fixes[0].model_sigma_um, 9.0);
  EXPECT_NEAR(fixes[1].model_sigma_um, 9.0, 1e-6);
  EXPECT_NEAR(fixes[2].model_sigma_um, 9.0, 1e-6);
}

// Where the filter keeps x's scale as a state, a merged fix's σ gains no scale share
// between crossings: the state carries it (counted twice, the strips would weigh less).
TEST(CrossingFixes, WhereTheScaleIsAStateTheMergedFixesAddNoScaleShare) {
  std::vector<PositionFix> fixes;
  std::vector<double> pos_mm;
  cross(fixes, pos_mm, 0, 0, 500, 10.0, 20.0, 5e-4, 0.0);
  cross(fixes, pos_mm, 1, 2000, 500, 40.0, 50.0, 5e-4, 0.0);
  for (auto& f : fixes) f.model_sigma_um = 2.0;  // the mounting's share across the axis
  std::vector<PositionFix> as_noise = fixes;
  std::vector<double> as_noise_pos = pos_mm;
  merge_crossings(as_noise, as_noise_pos, 3e-4, 20);
  merge_crossings(fixes, pos_mm, 3e-4, 20, {300.0, 0.0, 0.0});
  ASSERT_EQ(fixes.size(), 2u);
  ASSERT_EQ(as_noise.size(), 2u);
  EXPECT_NEAR(as_noise[1].model_sigma_um, 9.0, 1e-6);  // 30 mm at 3e-4 between the crossings
  EXPECT_DOUBLE_EQ(fixes[0].model_sigma_um, 2.0);
  EXPECT_DOUBLE_EQ(fixes[1].model_sigma_um, 2.0);
}

TEST(CrossingFixes, ASecondPassOverTheSameStripIsPinnedToItsReadings) {
  std::vector<PositionFix> fixes;
  std::vector<double> pos_mm;
  cross(fixes, pos_mm, 0, 0, 500, 10.0, 20.0, 5e-4, 0.0);
  cross(fixes, pos_mm, 0, 9000, 500, 20.0, 10.0, 5e-4, 0.0);
  for (auto& f : fixes) f.model_sigma_um = 4.5;
  merge_crossings(fixes, pos_mm, 3e-4, 20);
  ASSERT_EQ(fixes.size(), 2u);
  EXPECT_DOUBLE_EQ(fixes[0].model_sigma_um, 4.5);
  EXPECT_NEAR(fixes[1].model_sigma_um, 0.0, 1e-9);
}

}  // namespace
}  // namespace eical::dsp::fusion
