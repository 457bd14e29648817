// Repeat segmentation and averaging on a synthetic trace: four passes of one path plus
// one different segment; the mean keeps the systematic deviation, the spread is the
// per-pass noise, the odd segment is not averaged in.
#include "dsp/eval/repeats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace eical::dsp::eval {
namespace {

TEST(Repeats, AveragesIdenticalPassesAndMeasuresTheirScatter) {
  const std::size_t pass = 1000;
  std::vector<std::int64_t> idx;
  std::vector<Eigen::Vector3d> pos, cmd;
  std::vector<std::int64_t> marks;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1e-3);  // 1 µm per pass, constant within a pass
  std::int64_t k = 0;
  for (int r = 0; r < 5; ++r) {
    marks.push_back(k);
    const double offset = g(rng);
    for (std::size_t i = 0; i < pass; ++i, ++k) {
      const double t = static_cast<double>(i) / pass;
      Eigen::Vector3d c(10.0 * std::cos(2 * M_PI * t), 10.0 * std::sin(2 * M_PI * t), 0.0);
      if (r == 4) c = Eigen::Vector3d(5.0 * t, 0.0, 0.0);  // a different segment
      idx.push_back(k);
      cmd.push_back(c);
      const double systematic_mm = 2e-3 * std::sin(4 * M_PI * t);
      pos.push_back(c + Eigen::Vector3d(systematic_mm + offset, 0.0, 0.0));
    }
  }
  marks.push_back(k - 1);
  RepeatInput in;
  in.sample_index = &idx, in.pos_mm = &pos, in.cmd_mm = &cmd, in.marks = marks;
  const auto groups = average_repeats(in);
  ASSERT_EQ(groups.size(), 1u);
  const RepeatGroup& gr = groups[0];
  EXPECT_EQ(gr.repeats(), 4);
  EXPECT_EQ(gr.first_index.front(), 0);
  // Mean = systematic + mean offset; spread = std of the offsets (constant along the pass).
  const double quarter = gr.mean_deviation_um[250].x() - gr.mean_deviation_um[0].x();
  EXPECT_NEAR(quarter, 0.0, 1e-9);  // sin(π) − sin(0)
  EXPECT_NEAR(gr.mean_deviation_um[125].x() - gr.mean_deviation_um[0].x(), 2.0, 1e-9);
  EXPECT_NEAR(gr.spread_um[10].x(), gr.spread_um[900].x(), 1e-9);
  EXPECT_GT(gr.scatter_rms_um, 0.1);
  EXPECT_LT(gr.scatter_rms_um, 3.0);
}

TEST(Repeats, NoMarksNoGroups) {
  std::vector<std::int64_t> idx{0, 1, 2};
  std::vector<Eigen::Vector3d> p(3, Eigen::Vector3d::Zero());
  RepeatInput in;
  in.sample_index = &idx, in.pos_mm = &p, in.cmd_mm = &p;
  EXPECT_TRUE(average_repeats(in).empty());
}

}  // namespace
}  // namespace eical::dsp::eval
