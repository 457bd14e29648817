// eical plan: the uncertainty of a test's figures before anything moves, and the nearest
// measurable variant (tools/plan/test_plan.hpp).
#include "dsp/analysis/verdict.hpp"
#include "tools/commands.hpp"
#include "tools/figure_text.hpp"
#include "tools/io/psd_option.hpp"
#include "tools/plan/test_plan.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <memory>

namespace eical::tools {
namespace {

nlohmann::json prediction_json(const plan::Prediction& p) {
  nlohmann::json u = nlohmann::json::object();
  for (const auto& [k, v] : p.u_k2) u[k] = v;
  return {{"program", plan::describe(p.program)},
          {"duration_s", p.duration_s},
          {"uncertainty_k2", u},
          {"limited", p.limited},
          {"limited_u", std::isfinite(p.limited_u) ? nlohmann::json(p.limited_u) : nlohmann::json(nullptr)},
          {"limit", p.limit},
          {"measurable", p.measurable}};
}

std::string prediction_text(const plan::Prediction& p) {
  std::string o = "test: " + plan::describe(p.program) + "\n";
  char b[200];
  std::snprintf(b, sizeof b, "  runs %.1f s; predicted expanded uncertainty (k = 2) of its figures:\n", p.duration_s);
  o += b;
  for (const auto& [k, v] : p.u_k2) {
    std::snprintf(b, sizeof b, "    %-40s U = %s%s\n", k.c_str(), value_with_u(v, std::nullopt, figure_unit(k)).c_str(),
                  k == p.limited ? "   <- what the test must resolve" : "");
    o += b;
  }
  // value_with_u prints "± ?" without an uncertainty: the value here is U itself.
  // (" ± ?" is five bytes in UTF-8: erasing four left "µm?" on every line.)
  const std::string no_u = " ± ?";
  for (std::string::size_type at; (at = o.find(no_u)) != std::string::npos;) o.erase(at, no_u.size());
  std::snprintf(b, sizeof b, "  %s: U = %.2f µm %s the %.0f µm the test is meant to resolve\n",
                p.measurable ? "measurable" : "NOT MEASURABLE", p.limited_u, p.measurable ? "within" : "exceeds",
                p.limit);
  return o + b;
}

// What `eical plan` is told: the test program, its strips, how hard to look.
struct PlanCommandOptions {
  plan::TestProgram p;
  std::string psd = "none";
  std::vector<std::string> strips;
  std::vector<double> size{50.0, 50.0};
  bool json = false;
  int draws = 100;
  double max_s = 60.0;
};

void add_plan_options(CLI::App& cmd, PlanCommandOptions& o) {
  cmd.add_option("--program", o.p.kind, "circle, positioning, step or rectangle")
      ->default_val("circle")
      ->check(CLI::IsMember({"circle", "positioning", "step", "rectangle"}));
  cmd.add_option("--radius", o.p.radius_mm, "circle radius, mm")->default_val(10.0)->check(CLI::PositiveNumber);
  cmd.add_option("--feed", o.p.feed_mm_min, "feed, mm/min")->default_val(2500.0)->check(CLI::PositiveNumber);
  cmd.add_option("--repeats", o.p.repeats, "circle revolutions per direction, rectangle laps")
      ->default_val(5)
      ->check(CLI::Range(1, 1000));
  cmd.add_option("--direction", o.p.direction, "circle: ccw, cw or both")
      ->default_val("ccw")
      ->check(CLI::IsMember({"ccw", "cw", "both"}));
  cmd.add_option("--plane", o.p.plane, "circle, rectangle: xy, zx or yz")
      ->default_val("xy")
      ->check(CLI::IsMember({"xy", "zx", "yz"}));
  cmd.add_option("--arc-deg", o.p.arc_deg, "circle: evaluated arc in deg")
      ->default_val(360.0)
      ->check(CLI::Range(1.0, 360.0));
  cmd.add_option("--targets", o.p.targets_mm, "positioning: targets on x, mm (comma separated)")->delimiter(',');
  cmd.add_option("--runs", o.p.runs, "positioning: runs; step: there-and-back pairs")
      ->default_val(5)
      ->check(CLI::Range(1, 1000));
  cmd.add_option("--from", o.p.from_mm, "step: start on x, mm")->default_val(0.0);
  cmd.add_option("--to", o.p.to_mm, "step: end on x, mm")->default_val(50.0);
  cmd.add_option("--size", o.size, "rectangle: side lengths, mm (two values, comma separated)")
      ->expected(2)
      ->delimiter(',');
  cmd.add_option("--psd", o.psd,
                 "PSD strips: none, B (configuration B about the circle, one at mid travel, mid sides of a rectangle)")
      ->default_val("none")
      ->check(CLI::IsMember({"none", "B"}));
  cmd.add_option("--strip", o.strips, "a strip on the machine as MEASURES:CX,CY, e.g. x:0,-10 (repeat for each)");
  cmd.add_option("--noise", o.p.noise_ug_per_rthz, "each sensor's noise density, ug/sqrt(Hz) (two-sided)")
      ->default_val(0.4)
      ->check(CLI::PositiveNumber);
  cmd.add_option("--fs", o.p.fs_hz, "DAQ sampling rate, Hz")->default_val(10000.0)->check(CLI::Range(1000.0, 100000.0));
  cmd.add_option("--draws", o.draws, "Monte Carlo draws per prediction")
      ->default_val(100)
      ->check(CLI::Range(10, 100000));
  cmd.add_option("--max-duration", o.max_s, "variants that run longer than this (s) are not tried")
      ->default_val(60.0)
      ->check(CLI::PositiveNumber);
  cmd.add_flag("--json", o.json, "print the prediction as JSON");
}

// The test as asked: its rectangle size and PSD strips.
plan::TestProgram test_program(const PlanCommandOptions& o) {
  plan::TestProgram p = o.p;
  p.size_mm[0] = o.size.at(0), p.size_mm[1] = o.size.at(1);
  if (o.psd == "B") p.psd = plan::strips_for(p);
  for (const auto& s : o.strips) p.psd.push_back(parse_psd(s));
  return p;
}

void run_plan(const PlanCommandOptions& o) {
  const plan::TestProgram p = test_program(o);
  const plan::Prediction r = plan::predict(p, 1, o.draws);
  std::optional<plan::Prediction> better;
  if (!r.measurable) better = plan::nearest_measurable(p, o.max_s, o.draws);
  if (o.json) {
    nlohmann::json j = {{"format", "eical-plan/1"}, {"prediction", prediction_json(r)}};
    j["nearest_measurable"] = better ? prediction_json(*better) : nlohmann::json(nullptr);
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::string text = prediction_text(r);
  if (!r.measurable) {
    if (better)
      text += "\nnearest measurable variant:\n" + prediction_text(*better);
    else {
      text += "\nno variant within " + std::to_string(static_cast<int>(o.max_s)) + " s is measurable; tried:\n";
      for (const auto& v : plan::variants(p)) text += "  " + plan::describe(v) + "\n";
    }
  }
  std::fputs(text.c_str(), stdout);
}

}  // namespace

void register_plan(CLI::App& app) {
  auto o = std::make_shared<PlanCommandOptions>();
  auto* cmd = app.add_subcommand(
      "plan", "Predict the uncertainty of a test before it runs; propose the nearest measurable variant");
  add_plan_options(*cmd, *o);
  cmd->callback([o] { run_plan(*o); });
}

}  // namespace eical::tools
