#include "tools/plan/identification_plan.hpp"

#include "dsp/core/axes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::tools::plan {

namespace {

std::string mm(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", std::abs(v) < 5e-7 ? 0.0 : v);
  return b;
}

}  // namespace

void test_travel(const TestProgram& p, std::optional<sim::gcode::AxisTravel> (&travel_mm)[2]) {
  travel_mm[0].reset(), travel_mm[1].reset();
  if (p.kind == dsp::ProgramKind::circle) {
    const sim::gcode::AxisTravel t{-p.radius_mm, p.radius_mm};
    if (p.plane == "xy" || p.plane == "zx") travel_mm[0] = t;
    if (p.plane == "xy" || p.plane == "yz") travel_mm[1] = t;
  } else if (p.kind == dsp::ProgramKind::positioning && !p.targets_mm.empty()) {
    const auto [lo, hi] = std::minmax_element(p.targets_mm.begin(), p.targets_mm.end());
    travel_mm[0] = sim::gcode::AxisTravel{*lo, *hi};
  } else if (p.kind == dsp::ProgramKind::step) {
    travel_mm[0] = sim::gcode::AxisTravel{std::min(p.from_mm, p.to_mm), std::max(p.from_mm, p.to_mm)};
  } else if (p.kind == dsp::ProgramKind::rectangle) {
    travel_mm[0] = sim::gcode::AxisTravel{0.0, p.size_mm[0]};
    travel_mm[1] = sim::gcode::AxisTravel{0.0, p.size_mm[1]};
  }
  for (auto& t : travel_mm)
    if (t && !(t->hi_mm > t->lo_mm)) t.reset();  // a test that holds the axis
}

sim::gcode::IdentifyPlan identification_plan(const TestProgram& p) {
  sim::gcode::IdentifyPlan plan;
  plan.psd = p.psd.empty() ? strips_for(p) : p.psd;
  plan.axes = {"z"};
  test_travel(p, plan.travel_mm);
  if (p.kind == dsp::ProgramKind::circle) {
    // A circle crosses each strip where it is mounted, and a strip turned radial sits on the
    // circle's ends: the swing runs on beyond the circle just far enough to cross it whole
    // (a tenth of its length clear of each end).
    for (const auto& s : plan.psd) {
      const int along = dsp::axis_index(s.measures);
      if (along < 0 || along > 1 || !plan.travel_mm[along]) continue;
      auto& t = *plan.travel_mm[along];
      const double reach_mm = 0.6 * s.length_mm;
      t.lo_mm = std::min(t.lo_mm, s.center_mm[along] - reach_mm);
      t.hi_mm = std::max(t.hi_mm, s.center_mm[along] + reach_mm);
    }
  }
  return plan;
}

std::string identification_command(const sim::gcode::IdentifyPlan& plan) {
  std::string c = "eical gen-nc identify";
  for (const auto& s : plan.psd) c += " --psd " + s.measures + ":" + mm(s.center_mm[0]) + "," + mm(s.center_mm[1]);
  for (const auto& a : plan.axes) c += " --axis " + a;
  for (int k = 0; k < 2; ++k)
    if (plan.travel_mm[k])
      c += std::string(" --travel ") + (k == 0 ? "x" : "y") + ":" + mm(plan.travel_mm[k]->lo_mm) + "," +
           mm(plan.travel_mm[k]->hi_mm);
  return c;
}

std::string identification_text(const sim::gcode::IdentifyPlan& plan) {
  std::string o = "  identify first, across the same strips (" + identification_command(plan) + "):\n";
  char b[200];
  for (const auto& s : plan.psd) {
    const auto w = sim::gcode::strip_swing(plan, s);
    std::snprintf(b, sizeof b, "    %s swings %s … %s mm across the strip at %s = %s mm\n", s.measures.c_str(),
                  mm(w.centre_mm - w.half_mm).c_str(), mm(w.centre_mm + w.half_mm).c_str(),
                  s.measures == "x" ? "y" : "x", mm(s.center_mm[s.measures == "x" ? 1 : 0]).c_str());
    o += b;
  }
  for (const auto& a : plan.axes)
    o += "    " + a + " swings ± " + mm(plan.swing_mm / 2.0) + " mm about where it rests\n";
  o += "    every swing stays inside --travel (the test's own; about a circle as far beyond it as a strip on its "
       "end needs to be crossed whole) where it spans the " +
       mm(plan.swing_mm) + " mm swing, and is centred on a shorter one\n";
  return o;
}

nlohmann::json identification_json(const sim::gcode::IdentifyPlan& plan) {
  nlohmann::json swings = nlohmann::json::array();
  for (const auto& s : plan.psd) {
    const auto w = sim::gcode::strip_swing(plan, s);
    swings.push_back({{"axis", s.measures},
                      {"from_mm", w.centre_mm - w.half_mm},
                      {"to_mm", w.centre_mm + w.half_mm},
                      {"strip_center_mm", {s.center_mm[0], s.center_mm[1]}}});
  }
  for (const auto& a : plan.axes)
    swings.push_back({{"axis", a}, {"relative_mm", plan.swing_mm / 2.0}, {"about", "where it rests"}});
  return {{"command", identification_command(plan)}, {"swings", swings}};
}

}  // namespace eical::tools::plan
