#pragma once
// `eical plan` against simulation: for a program, the predicted U of its headline figures
// (plan::predict, one simulated run on an ideal machine) beside the spread of the same
// figures over repeats of the program on machines drawn within the data sheet's
// tolerances, each against the simulator's truth. The empirical U of a figure is
// |mean error| + 2·(sd of the error) over the repeats — the 95 % bound that U claims, bias
// included (a range such as G is biased by the noise).
#include "tools/plan/predicted_uncertainty.hpp"

#include <string>
#include <vector>

namespace eical::tools::plan {

struct CheckRow {
  std::string program, key;
  double predicted_u = 0.0, empirical_u = 0.0;
  double mean_error = 0.0, sd_error = 0.0;
  int repeats = 0, degraded = 0;
  [[nodiscard]] double ratio() const { return empirical_u > 0.0 ? predicted_u / empirical_u : 0.0; }
};

// The programs of the check (at least four): a circle with strips, a 1-D step, an ISO
// 230-2 cycle and a rectangle; `repeats` seeds each.
// With p.identified every repeat's machine is first identified by the identification
// program (tools/plan/predicted_uncertainty.hpp), as a user of a measurable test would.
// `identified`: each program after an on-site identification of the sensors (the plan's
// measurable variants), else on the data sheet's sensor model.
std::vector<TestProgram> check_programs(bool identified = true);
std::vector<CheckRow> check_plan(const TestProgram& p, int repeats, int draws = 100);

std::string check_table(const std::vector<CheckRow>& rows);

}  // namespace eical::tools::plan
