// Issue 3's proof: the simulator reproduces the thesis' figures within the stated
// tolerances (the table `eical validate-sim` prints).
#include "tools/validate/thesis_checks.hpp"

#include <gtest/gtest.h>

namespace eical::tools {
namespace {

TEST(ValidateSim, EveryThesisFigureWithinItsTolerance) {
  const auto rows = validate_against_thesis({.monte_carlo_windows = 300, .seed = 3});
  ASSERT_GE(rows.size(), 8u);
  for (const auto& r : rows) {
    std::printf("%-60s thesis %8.3g %s  simulated %8.3g %s  ratio %.3f\n", r.name.c_str(), r.thesis, r.unit.c_str(),
                r.simulated, r.unit.c_str(), r.ratio());
    EXPECT_TRUE(r.within()) << r.name << ": ratio " << r.ratio() << " outside " << r.ratio_min << ".." << r.ratio_max;
    EXPECT_GT(r.simulated, 0.0) << r.name;
  }
}

}  // namespace
}  // namespace eical::tools
