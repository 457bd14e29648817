// NBS (Bild 7-8) on the rectangle: a sensor bias that changes between the moves (each
// partial move its own offset, ch. 8.3.2) makes the axis that stands still on a side drift
// during the side; holding that axis removes it. The corners are ZUPT's business. The
// machine is ideal, so every error is measurement error.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/float_limits.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace eical {
namespace {

double worst_corner_um(const dsp::Analysis& a) {
  double worst = 0.0;
  for (const auto& e : a.rectangle->corner_errors_um) worst = std::max(worst, e.norm());
  return worst;
}

// Largest change (µm) of the error of the axis that stands still while the other moves,
// over one side: its drift along the side (its offset at the corner is ZUPT's).
double still_axis_drift_um(const dsp::Measurement& m) {
  double worst = 0.0;
  std::size_t k = 1;
  while (k < m.pos_mm.size()) {
    const Eigen::Vector3d d = m.cmd_mm[k] - m.cmd_mm[k - 1];
    const int still = d[0] != 0.0 && d[1] == 0.0 ? 1 : (d[1] != 0.0 && d[0] == 0.0 ? 0 : -1);
    if (still < 0) {
      ++k;
      continue;
    }
    double lo = kInf, hi = -kInf;
    for (; k < m.pos_mm.size() && (m.cmd_mm[k] - m.cmd_mm[k - 1])[1 - still] != 0.0; ++k) {
      const double e = (m.pos_mm[k][still] - m.ref_mm[k][still]) * 1e3;
      lo = std::min(lo, e), hi = std::max(hi, e);
    }
    worst = std::max(worst, hi - lo);
  }
  return worst;
}

TEST(NbsRectangle, HoldingTheStillAxisRemovesItsDrift) {
  sim::Scenario sc = sim::rectangle_scenario(50.0, 50.0, 6500.0, "xy", 1, 4);
  sc.noise = false;
  sc.truth[0].bias_step_ug = 3.0;  // the table sensor's bias jumps at every move start
  const dsp::Run run = sim::simulate(sc);
  dsp::AnalysisOptions off;
  off.nbs = false;
  const dsp::Analysis with = dsp::analyze_run(run), without = dsp::analyze_run(run, off);
  ASSERT_TRUE(with.rectangle && without.rectangle);
  EXPECT_TRUE(with.nbs);  // on by default for rectangles
  const double w = still_axis_drift_um(with.measurement), wo = still_axis_drift_um(without.measurement);
  std::printf(
      "3 ug bias step per move, 50 mm rectangle at 6.5 m/min: still axis drift along a side without NBS %.2f um, with "
      "%.2f um; "
      "worst corner %.2f / %.2f um\n",
      wo, w, worst_corner_um(without), worst_corner_um(with));
  EXPECT_LT(w, 0.25 * wo);
  EXPECT_LT(w, 0.05);
  EXPECT_LT(worst_corner_um(with), 1.5 * worst_corner_um(without) + 0.5);  // the corners stay ZUPT's
}

TEST(NbsRectangle, IdealRunIsUnchangedWhereAxesMove) {
  // With nothing to remove, NBS changes the moving axis by nothing and holds the still one
  // where it already is.
  sim::Scenario sc = sim::rectangle_scenario(50.0, 50.0, 6500.0, "xy", 1, 4);
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 4e-9;
  const dsp::Run run = sim::simulate(sc);
  const dsp::Analysis a = dsp::analyze_run(run);
  ASSERT_TRUE(a.rectangle);
  EXPECT_LT(worst_corner_um(a), 0.05);
}

}  // namespace
}  // namespace eical
