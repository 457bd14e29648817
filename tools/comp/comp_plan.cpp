#include "tools/comp/comp_plan.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <map>

namespace eical::tools::comp {
namespace {

using dsp::comp::AxisTable;

std::pair<int, int> plane_axes(const std::string& plane) {
  if (plane == "zx") return {2, 0};
  if (plane == "yz") return {1, 2};
  return {0, 1};
}

std::string letter(int a) { return std::string(1, dsp::comp::axis_letter(a)); }

struct PositioningData {
  const CompInput* in = nullptr;
  AxisTable table;  // as measured: x̄i↑, x̄i↓
};

PositioningData positioning_of(const CompInput& in) {
  const auto& p = in.result["positioning"];
  PositioningData d;
  d.in = &in;
  d.table.axis = dsp::axis_index(p.value("axis", std::string()));
  if (d.table.axis < 0) throw dsp::InputError(in.name + ": positioning.axis is not x, y or z");
  if (!p.contains("per_target") || !p["per_target"].is_array())
    throw dsp::InputError(in.name +
                          ": positioning.per_target is missing (a result older than eical comp's input format)");
  for (const auto& t : p["per_target"]) {
    if (!t.value("target_mm", nlohmann::json()).is_number() || !t.value("mean_up_um", nlohmann::json()).is_number() ||
        !t.value("mean_down_um", nlohmann::json()).is_number())
      throw dsp::InputError(in.name +
                            ": positioning.per_target has a target without target_mm, mean_up_um or mean_down_um");
    d.table.pos_mm.push_back(t["target_mm"].get<double>());
    d.table.forward_um.push_back(t["mean_up_um"].get<double>());
    d.table.reverse_um.push_back(t["mean_down_um"].get<double>());
  }
  dsp::comp::validate(d.table);
  return d;
}

bool has_numbers(const nlohmann::json& r, const char* section, const char* key) {
  return r.contains(section) && r[section].is_object() && r[section].contains(key) && r[section][key].is_number();
}

}  // namespace

Plan build_plan(const std::vector<CompInput>& inputs, const PlanOptions& o) {
  Plan plan;
  std::array<std::vector<PositioningData>, 3> pos;
  std::array<std::vector<Figure>, 3> backlash;
  std::vector<TravelRange> travel = o.travel;
  for (const auto& in : inputs) {
    const auto& r = in.result;
    bool used = false;
    if (has_numbers(r, "positioning", "A_um")) {
      PositioningData d = positioning_of(in);
      travel.push_back(
          {d.table.axis, d.table.first_mm(), d.table.last_mm(), "positioning run " + in.name + " measured"});
      pos[static_cast<std::size_t>(d.table.axis)].push_back(std::move(d));
      used = true;
    }
    if (has_numbers(r, "diagnostics", "backlash_x_um") && r.contains("circle") && r["circle"].is_object()) {
      const auto [u, v] = plane_axes(r["circle"].value("plane", std::string("xy")));
      backlash[static_cast<std::size_t>(u)].push_back(figure(in, "diagnostics.backlash_x_um"));
      if (has_numbers(r, "diagnostics", "backlash_y_um"))
        backlash[static_cast<std::size_t>(v)].push_back(figure(in, "diagnostics.backlash_y_um"));
      for (const char* k : {"diagnostics.squareness_urad", "diagnostics.scale_mismatch_ppm"})
        if (has_numbers(r, "diagnostics", std::string(k).substr(12).c_str())) {
          nlohmann::json j = figure(in, k).to_json();
          j["reason"] = std::string(
              "no axis table holds it: LinuxCNC's trivkins has no such term; SINUMERIK, FANUC and HEIDENHAIN need "
              "cross-axis tables eical does not write; it enters the volumetric model (eical volumetric --fit)");
          plan.not_compensated.push_back(j);
        }
      // The circle's travel on its two axes: centre ± radius.
      std::optional<std::array<double, 2>> centre;
      if (r["circle"].contains("center_mm") && r["circle"]["center_mm"].is_array() &&
          r["circle"]["center_mm"].size() == 2)
        centre =
            std::array<double, 2>{r["circle"]["center_mm"][0].get<double>(), r["circle"]["center_mm"][1].get<double>()};
      else if (in.program)
        centre = std::array<double, 2>{in.program->center_mm[0], in.program->center_mm[1]};
      const double radius = r["circle"].value("radius_nominal_mm", 0.0);
      if (!centre)
        throw dsp::InputError(in.name +
                              ": circle.center_mm is missing: give the run directory (its run.toml names the centre)");
      travel.push_back({u, (*centre)[0] - radius, (*centre)[0] + radius, "circle run " + in.name + " measured"});
      travel.push_back({v, (*centre)[1] - radius, (*centre)[1] + radius, "circle run " + in.name + " measured"});
      used = true;
    }
    if (!used)
      plan.skipped.push_back(
          {{"input", in.name},
           {"reason", "program '" + r.value("program", std::string("?")) +
                          "' gives no compensation terms (positioning runs give tables, circles backlash)"}});
  }

  std::vector<std::string> refused;
  // Whether compensation may be built on f; records the figure and its use either way.
  auto usable = [&](const Figure& f, const std::string& use) {
    nlohmann::json j = f.to_json();
    j["used_for"] = use;
    const bool ok = f.resolved() || o.unresolved == Unresolved::allow;
    j["proposed"] = ok;
    plan.figures.push_back(j);
    if (!f.resolved()) {
      if (o.unresolved == Unresolved::allow) plan.unresolved_used.push_back(f.describe());
      if (o.unresolved == Unresolved::refuse) refused.push_back(f.describe() + " (for the " + use + ")");
      if (o.unresolved == Unresolved::skip) plan.unresolved_skipped.push_back(f.describe() + " (for the " + use + ")");
    }
    return ok;
  };

  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    if (pos[ai].size() > 1)
      throw dsp::InputError("comp: " + std::to_string(pos[ai].size()) + " positioning runs measure " + letter(a) +
                            " (" + pos[ai][0].in->name + ", " + pos[ai][1].in->name + "): give one per axis");
    std::optional<Figure> circle_b;
    if (!backlash[ai].empty()) circle_b = combined(backlash[ai]);
    AxisProposal p;
    p.axis = a;
    if (!pos[ai].empty()) {
      const PositioningData& d = pos[ai][0];
      const Figure m = figure(*d.in, "positioning.M_um"), bm = figure(*d.in, "positioning.B_mean_um");
      const bool pitch = usable(m, letter(a) + " table (mean bidirectional deviation M)");
      // The reversal: the run's own if resolved; else the circles'; else none.
      enum { none, run, circle } reversal = none;
      if (bm.resolved() || !circle_b || !circle_b->resolved()) {
        if (usable(bm, letter(a) + " table reversal (mean reversal B)")) reversal = run;
      } else if (usable(*circle_b, letter(a) + " table reversal (circle backlash folded in)")) {
        reversal = circle;
      }
      if (circle_b && reversal == run)
        plan.figures.push_back([&] {
          nlohmann::json j = circle_b->to_json();
          j["used_for"] = "cross-check only: the " + letter(a) + " table carries the positioning run's own reversal";
          j["proposed"] = false;
          return j;
        }());
      std::vector<double> mean;
      for (std::size_t i = 0; i < d.table.pos_mm.size(); ++i) mean.push_back(d.table.mean_um(i));
      const std::string src = "positioning run " + d.in->name + (d.in->run_id.empty() ? "" : " (" + d.in->run_id + ")");
      if (pitch) {
        if (reversal == run)
          p.table = d.table, p.source = src + ", reversal as measured";
        else if (reversal == circle)
          p.table = dsp::comp::fold_lost_motion(a, d.table.pos_mm, mean, circle_b->value),
          p.source = src + ", backlash of " + circle_b->input + " folded in";
        else
          p.table = dsp::comp::without_reversal(d.table), p.source = src + ", no reversal (not resolved)";
      } else if (reversal != none) {
        p.lost_motion_um = reversal == run ? -bm.value : circle_b->value;  // ISO 230-2 B of a play is −b
        p.source = reversal == run ? src + ", mean reversal only" : "backlash of " + circle_b->input;
      }
    } else if (circle_b) {
      if (usable(*circle_b, letter(a) + " backlash"))
        p.lost_motion_um = circle_b->value, p.source = "backlash of " + circle_b->input;
    }
    if (p.table) {
      for (const auto& t : travel)
        if (t.axis == a) dsp::comp::require_coverage(*p.table, t.from_mm, t.to_mm, t.who);
    }
    if (p.table || p.lost_motion_um) plan.axes.push_back(p);
  }
  if (!refused.empty()) {
    std::string msg =
        "comp: no compensation from figures that are not resolved (|value| must exceed U, k = 2); nothing written:";
    for (const auto& r : refused) msg += "\n  " + r;
    msg +=
        "\n  measure again (more runs or revolutions), --skip-unresolved to leave these terms out, or "
        "--allow-unresolved to propose them anyway";
    throw dsp::InputError(msg);
  }
  if (plan.axes.empty() && plan.figures.empty())
    throw dsp::InputError("comp: none of the inputs is a circle or positioning result that could be evaluated");
  return plan;
}

}  // namespace eical::tools::comp
