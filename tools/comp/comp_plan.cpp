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

// What the inputs measured: positioning runs and circle backlash figures per axis, and
// the travel every input covered (besides --travel).
struct Measured {
  std::array<std::vector<PositioningData>, 3> pos;
  std::array<std::vector<Figure>, 3> backlash;
  std::vector<TravelRange> travel;
};

void add_positioning(const CompInput& in, Measured& m) {
  PositioningData d = positioning_of(in);
  m.travel.push_back({d.table.axis, d.table.first_mm(), d.table.last_mm(), "positioning run " + in.name + " measured"});
  m.pos[static_cast<std::size_t>(d.table.axis)].push_back(std::move(d));
}

// A circle: the backlash of its plane's two axes, its squareness and scale mismatch as
// figures no axis table holds, and its travel on both axes (centre ± radius).
void add_circle(const CompInput& in, Measured& m, Plan& plan) {
  const auto& r = in.result;
  const auto [u, v] = plane_axes(r["circle"].value("plane", std::string("xy")));
  m.backlash[static_cast<std::size_t>(u)].push_back(figure(in, "diagnostics.backlash_x_um"));
  if (has_numbers(r, "diagnostics", "backlash_y_um"))
    m.backlash[static_cast<std::size_t>(v)].push_back(figure(in, "diagnostics.backlash_y_um"));
  for (const char* k : {"diagnostics.squareness_urad", "diagnostics.scale_mismatch_ppm"})
    if (has_numbers(r, "diagnostics", std::string(k).substr(12).c_str())) {
      nlohmann::json j = figure(in, k).to_json();
      j["reason"] = std::string(
          "no axis table holds it: LinuxCNC's trivkins has no such term; SINUMERIK, FANUC and HEIDENHAIN need "
          "cross-axis tables eical does not write; it enters the volumetric model (eical volumetric --fit)");
      plan.not_compensated.push_back(j);
    }
  std::optional<std::array<double, 2>> centre;
  if (r["circle"].contains("center_mm") && r["circle"]["center_mm"].is_array() && r["circle"]["center_mm"].size() == 2)
    centre =
        std::array<double, 2>{r["circle"]["center_mm"][0].get<double>(), r["circle"]["center_mm"][1].get<double>()};
  else if (in.program)
    centre = std::array<double, 2>{in.program->center_mm[0], in.program->center_mm[1]};
  const double radius = r["circle"].value("radius_nominal_mm", 0.0);
  if (!centre)
    throw dsp::InputError(in.name +
                          ": circle.center_mm is missing: give the run directory (its run.toml names the centre)");
  m.travel.push_back({u, (*centre)[0] - radius, (*centre)[0] + radius, "circle run " + in.name + " measured"});
  m.travel.push_back({v, (*centre)[1] - radius, (*centre)[1] + radius, "circle run " + in.name + " measured"});
}

// Sorts the inputs; one that gives no compensation term is recorded as skipped.
Measured measured_of(const std::vector<CompInput>& inputs, const std::vector<TravelRange>& travel, Plan& plan) {
  Measured m;
  m.travel = travel;
  for (const auto& in : inputs) {
    const auto& r = in.result;
    bool used = false;
    if (has_numbers(r, "positioning", "A_um")) {
      add_positioning(in, m);
      used = true;
    }
    if (has_numbers(r, "diagnostics", "backlash_x_um") && r.contains("circle") && r["circle"].is_object()) {
      add_circle(in, m, plan);
      used = true;
    }
    if (!used)
      plan.skipped.push_back(
          {{"input", in.name},
           {"reason", "program '" + r.value("program", std::string("?")) +
                          "' gives no compensation terms (positioning runs give tables, circles backlash)"}});
  }
  return m;
}

// Whether compensation may be built on a figure; records the figure and its use either
// way, and the unresolved ones as the caller chose (refused, skipped, allowed).
class FigureUse {
 public:
  FigureUse(Plan& plan, Unresolved unresolved) : plan_(plan), unresolved_(unresolved) {}

  bool usable(const Figure& f, const std::string& use) {
    nlohmann::json j = f.to_json();
    j["used_for"] = use;
    const bool ok = f.resolved() || unresolved_ == Unresolved::allow;
    j["proposed"] = ok;
    plan_.figures.push_back(j);
    if (!f.resolved()) {
      if (unresolved_ == Unresolved::allow) plan_.unresolved_used.push_back(f.describe());
      if (unresolved_ == Unresolved::refuse) refused_.push_back(f.describe() + " (for the " + use + ")");
      if (unresolved_ == Unresolved::skip) plan_.unresolved_skipped.push_back(f.describe() + " (for the " + use + ")");
    }
    return ok;
  }

  // A figure looked at but not used.
  void cross_check(const Figure& f, const std::string& why) {
    nlohmann::json j = f.to_json();
    j["used_for"] = why;
    j["proposed"] = false;
    plan_.figures.push_back(j);
  }

  // Nothing is proposed while an unresolved figure is refused.
  void throw_if_refused() const {
    if (refused_.empty()) return;
    std::string msg =
        "comp: no compensation from figures that are not resolved (|value| must exceed U, k = 2); nothing written:";
    for (const auto& r : refused_) msg += "\n  " + r;
    msg +=
        "\n  measure again (more runs or revolutions), leave out --refuse-unresolved to write the resolved terms, or "
        "--allow-unresolved to propose them anyway";
    throw dsp::InputError(msg);
  }

 private:
  Plan& plan_;
  Unresolved unresolved_;
  std::vector<std::string> refused_;
};

// An axis with a positioning run: its table (pitch: M) with the reversal folded in — the
// run's own if resolved; else the circles'; else none — or, the pitch not resolved, the
// lost motion alone.
void positioning_proposal(const PositioningData& d, const std::optional<Figure>& circle_b, FigureUse& use,
                          AxisProposal& p) {
  const int a = p.axis;
  const Figure m = figure(*d.in, "positioning.M_um"), bm = figure(*d.in, "positioning.B_mean_um");
  const bool pitch = use.usable(m, letter(a) + " table (mean bidirectional deviation M)");
  enum { none, run, circle } reversal = none;
  if (bm.resolved() || !circle_b || !circle_b->resolved()) {
    if (use.usable(bm, letter(a) + " table reversal (mean reversal B)")) reversal = run;
  } else if (use.usable(*circle_b, letter(a) + " table reversal (circle backlash folded in)")) {
    reversal = circle;
  }
  if (circle_b && reversal == run)
    use.cross_check(*circle_b,
                    "cross-check only: the " + letter(a) + " table carries the positioning run's own reversal");
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
}

// Axis a's proposal: from its positioning run (one at most), else from the circles'
// backlash; a table must cover every travel measured on the axis.
AxisProposal axis_proposal(int a, const Measured& m, FigureUse& use) {
  const auto ai = static_cast<std::size_t>(a);
  if (m.pos[ai].size() > 1)
    throw dsp::InputError("comp: " + std::to_string(m.pos[ai].size()) + " positioning runs measure " + letter(a) +
                          " (" + m.pos[ai][0].in->name + ", " + m.pos[ai][1].in->name + "): give one per axis");
  std::optional<Figure> circle_b;
  if (!m.backlash[ai].empty()) circle_b = combined(m.backlash[ai]);
  AxisProposal p;
  p.axis = a;
  if (!m.pos[ai].empty()) {
    positioning_proposal(m.pos[ai][0], circle_b, use, p);
  } else if (circle_b) {
    if (use.usable(*circle_b, letter(a) + " backlash"))
      p.lost_motion_um = circle_b->value, p.source = "backlash of " + circle_b->input;
  }
  if (p.table) {
    for (const auto& t : m.travel)
      if (t.axis == a) dsp::comp::require_coverage(*p.table, t.from_mm, t.to_mm, t.who);
  }
  return p;
}

}  // namespace

Plan build_plan(const std::vector<CompInput>& inputs, const PlanOptions& o) {
  Plan plan;
  const Measured m = measured_of(inputs, o.travel, plan);
  FigureUse use(plan, o.unresolved);
  for (int a = 0; a < 3; ++a) {
    AxisProposal p = axis_proposal(a, m, use);
    if (p.table || p.lost_motion_um) plan.axes.push_back(p);
  }
  use.throw_if_refused();
  if (plan.axes.empty() && plan.figures.empty())
    throw dsp::InputError("comp: none of the inputs is a circle or positioning result that could be evaluated");
  return plan;
}

}  // namespace eical::tools::comp
