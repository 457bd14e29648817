// eical plan: the uncertainty of a test's figures before anything moves, and the nearest
// measurable variant (tools/plan/predicted_uncertainty.hpp).
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/key_unit.hpp"
#include "dsp/core/sample_rate.hpp"
#include "sim/simulate.hpp"
#include "tools/commands.hpp"
#include "tools/envelope_options.hpp"
#include "tools/exit_codes.hpp"
#include "tools/figure_text.hpp"
#include "tools/io/psd_option.hpp"
#include "tools/plan/identification_plan.hpp"
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/plan/psd_layouts.hpp"
#include "tools/plan/strip_layout.hpp"
#include "tools/program_defaults.hpp"
#include "tools/program_kind_option.hpp"
#include "tools/run_files.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

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
          {"measurable", p.measurable},
          {"strips", plan::layout_json(p.program)},
          {"identification", p.program.identified ? plan::identification_json(plan::identification_plan(p.program))
                                                  : nlohmann::json(nullptr)}};
}

std::string prediction_text(const plan::Prediction& p) {
  std::string o = "test: " + plan::describe(p.program) + "\n";
  char b[200];
  std::snprintf(b, sizeof b, "  runs %.1f s; predicted expanded uncertainty (k = 2) of its figures:\n", p.duration_s);
  o += b;
  for (const auto& [k, v] : p.u_k2) {
    std::snprintf(b, sizeof b, "    %-40s U = %s%s\n", k.c_str(),
                  value_with_u(v, std::nullopt, dsp::unit_of_key(k)).c_str(),
                  k == p.limited ? "   <- what the test must resolve" : "");
    o += b;
  }
  // value_with_u prints "± ?" without an uncertainty: the value here is U itself.
  // (" ± ?" is five bytes in UTF-8: erasing four left "µm?" on every line.)
  const std::string no_u = " ± ?";
  for (std::string::size_type at; (at = o.find(no_u)) != std::string::npos;) o.erase(at, no_u.size());
  std::snprintf(b, sizeof b, "  %s: U = %.2f µm %s the %g µm the test is meant to resolve%s\n",
                p.measurable ? "measurable" : "NOT MEASURABLE", p.limited_u, p.measurable ? "within" : "exceeds",
                p.limit, p.program.resolve_um ? " (--resolve)" : "");
  return o + b + plan::layout_text(p.program) +
         (p.program.identified ? plan::identification_text(plan::identification_plan(p.program)) : std::string());
}

// What `eical plan` is told: the test program, its strips, how hard to look.
struct PlanCommandOptions {
  plan::TestProgram p;
  std::string psd = "none";
  std::vector<std::string> strips;
  std::vector<double> size{50.0, 50.0};
  bool json = false;
  std::string layout_svg, calibration;
  int draws = 100;
  double max_s = 180.0;
  double deadline_s = 60.0;
  EnvelopeOptions envelope;
  // Unset: the program kind's default (tools/program_defaults.hpp), the same as gen-nc's.
  std::optional<double> feed_mm_min;
  std::optional<int> runs, repeats;
};

void add_plan_options(CLI::App& cmd, PlanCommandOptions& o) {
  add_program_kind_option(
      cmd, "--program", o.p.kind,
      {dsp::ProgramKind::circle, dsp::ProgramKind::positioning, dsp::ProgramKind::step, dsp::ProgramKind::rectangle},
      "circle, positioning, step or rectangle");
  cmd.add_option("--radius", o.p.radius_mm, "circle radius, mm")
      ->default_val(program_defaults::kCircleRadiusMm)
      ->check(CLI::PositiveNumber);
  cmd.add_option("--feed", o.feed_mm_min, "feed, mm/min (default: gen-nc's for the program)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--repeats", o.repeats, "circle revolutions per direction, rectangle laps (default: gen-nc's)")
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
  cmd.add_option("--runs", o.runs, "positioning: runs; step: there-and-back pairs (default: gen-nc's)")
      ->check(CLI::Range(1, 1000));
  cmd.add_option("--from", o.p.from_mm, "step: start on x, mm")->default_val(0.0);
  cmd.add_option("--to", o.p.to_mm, "step: end on x, mm")->default_val(50.0);
  cmd.add_option("--size", o.size, "rectangle: side lengths, mm (two values, comma separated)")
      ->expected(2)
      ->delimiter(',');
  cmd.add_option("--psd", o.psd,
                 "PSD strips: none, B (configuration B about the circle, one at mid travel, mid sides of a "
                 "rectangle), B4, B8, B16 (that many strips evenly about the circle, along its path), R4, R8, R16 "
                 "(the same, turned radial)")
      ->default_val("none")
      ->check(CLI::IsMember(plan::psd_layout_names()));
  cmd.add_option("--strip", o.strips, "a strip on the machine as MEASURES:CX,CY, e.g. x:0,-10 (repeat for each)");
  cmd.add_option("--noise", o.p.noise_ug_per_rthz, "each sensor's noise density, ug/sqrt(Hz) (two-sided)")
      ->default_val(0.4)
      ->check(CLI::PositiveNumber);
  cmd.add_option("--fs", o.p.fs_hz, "DAQ sampling rate, Hz")
      ->default_val(dsp::kDefaultFs_hz)
      ->check(CLI::Range(1000.0, 100000.0));
  cmd.add_option("--draws", o.draws, "Monte Carlo draws per prediction")
      ->default_val(100)
      ->check(CLI::Range(10, 100000));
  cmd.add_option("--max-duration", o.max_s,
                 "the longest program simulated, s: a longer test is refused, longer variants are not tried")
      ->default_val(180.0)
      ->check(CLI::Range(1.0, 3600.0));
  cmd.add_option("--deadline", o.deadline_s,
                 "stop after this many seconds: no simulation starts later; what was not evaluated is listed "
                 "(exit status 6)")
      ->default_val(60.0)
      ->check(CLI::Range(0.0, 86400.0));
  cmd.add_option("--calibration", o.calibration,
                 "the machine's sensor calibration (eical-sensor-cal/1, from eical identify): the test and every "
                 "variant are predicted with its covariance, as identified")
      ->check(CLI::ExistingFile);
  cmd.add_flag("--identified", o.p.identified,
               "the sensors identified on site first (eical gen-nc identify, eical identify): the test and every "
               "variant predicted so, with a simulated identification");
  cmd.add_option("--resolve", o.p.resolve_um,
                 "the U (k = 2, µm) the test's limited figure must reach, e.g. 3 for a circle's G; default what the "
                 "program must resolve (a circle's G: 10 µm)")
      ->check(CLI::Range(0.01, 1000.0));
  cmd.add_flag("--json", o.json, "print the prediction as JSON");
  cmd.add_option("--layout-svg", o.layout_svg,
                 "draw the path and where its PSD strips go (the measurable test, else the nearest measurable "
                 "variant) into this SVG file");
  add_envelope_options(cmd, o.envelope);
}

// The test as asked: its rectangle size and PSD strips.
plan::TestProgram test_program(const PlanCommandOptions& o) {
  plan::TestProgram p = o.p;
  p.feed_mm_min = o.feed_mm_min.value_or(program_defaults::feed_mm_min(p.kind));
  p.runs = o.runs.value_or(program_defaults::runs(p.kind));
  p.repeats = o.repeats.value_or(program_defaults::repeats(p.kind));
  p.size_mm[0] = o.size.at(0), p.size_mm[1] = o.size.at(1);
  const plan::PsdLayout layout = plan::psd_layout(o.psd);
  p.psd = plan::strips_for(p, layout.strips, layout.facing);
  for (const auto& s : o.strips) p.psd.push_back(parse_psd(s));
  return p;
}

const char* outcome_text(plan::Outcome o) {
  switch (o) {
    case plan::Outcome::measurable: return "measurable";
    case plan::Outcome::not_measurable: return "not measurable";
    case plan::Outcome::too_long: return "not tried: runs longer than --max-duration";
    case plan::Outcome::outside_envelope: return "not tried: beyond the work envelope";
    case plan::Outcome::not_reached: return "NOT EVALUATED: the deadline passed";
  }
  return "";
}

std::string search_text(const plan::Search& s) {
  std::string o;
  char b[64];
  for (const auto& t : s.tried) {
    o += "  " + plan::describe(t.program) + ": " + outcome_text(t.outcome);
    if (t.outcome == plan::Outcome::measurable || t.outcome == plan::Outcome::not_measurable) {
      std::snprintf(b, sizeof b, " (U = %.2f µm)", t.limited_u);
      o += b;
    }
    o += "\n";
  }
  return o;
}

nlohmann::json search_json(const plan::Search& s) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& t : s.tried) {
    nlohmann::json v = {{"program", plan::describe(t.program)}, {"outcome", outcome_text(t.outcome)}};
    if (t.outcome == plan::Outcome::measurable || t.outcome == plan::Outcome::not_measurable)
      v["limited_u"] = t.limited_u;
    a.push_back(v);
  }
  return a;
}

// The test itself must be one plan can simulate: within the machine's envelope and not
// longer than --max-duration (its simulation's memory and time grow with its length).
void require_simulable(const plan::TestProgram& p, const PlanCommandOptions& o, const dsp::WorkEnvelope& e) {
  if (auto why = envelope_refusal(*sim::scenario_set_point(plan::scenario_of(p, 1)), e,
                                  "plan " + std::string(dsp::program_kind_name(p.kind))))
    throw dsp::InputError(*why);
  const double t_s = plan::program_duration_s(p);
  if (t_s > o.max_s) {
    char b[300];
    std::snprintf(b, sizeof b,
                  "plan %s: the test runs %.1f s, longer than the %.0f s plan simulates (--max-duration; the "
                  "simulation's time and memory grow with it)",
                  dsp::program_kind_name(p.kind), t_s, o.max_s);
    throw dsp::InputError(b);
  }
}

// The covariance of --calibration's file; a file without one is as uncertain as the data
// sheet, which is said, and the test is then predicted as not identified.
std::optional<dsp::SensorModelCovariance> calibration_covariance(const PlanCommandOptions& o, plan::TestProgram& p) {
  if (o.calibration.empty()) return std::nullopt;
  const drivers::SensorCalibration cal = drivers::read_sensor_calibration(o.calibration, plan::scenario_of(p, 1).meta);
  if (!cal.covariance) {
    std::fprintf(stderr,
                 "plan: %s has no [covariance]: the sensors are as uncertain as their data sheet, and the test is "
                 "predicted so\n",
                 o.calibration.c_str());
    p.identified = false;
    return std::nullopt;
  }
  std::fprintf(stderr, "plan: the sensors as calibrated by %s (run %s)\n", o.calibration.c_str(), cal.run_id.c_str());
  return cal.covariance;
}

void run_plan(const PlanCommandOptions& o) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point t0 = Clock::now();
  const auto elapsed_s = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  plan::TestProgram p = test_program(o);
  p.identified = p.identified || !o.calibration.empty();
  const dsp::WorkEnvelope envelope = envelope_of(o.envelope);
  require_simulable(p, o, envelope);
  const auto calibration = calibration_covariance(o, p);
  std::fprintf(stderr, "plan: simulating the test: %s\n", plan::describe(p).c_str());
  const plan::Prediction r = plan::predict(p, 1, o.draws, calibration);
  plan::Search search;
  if (!r.measurable) {
    plan::SearchOptions so;
    so.max_duration_s = o.max_s, so.draws = o.draws, so.envelope = envelope, so.calibration = calibration;
    so.deadline = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.deadline_s));
    so.progress = [&](int n, int of, const plan::TestProgram& t) {
      if (n == 0)
        std::fprintf(stderr,
                     "plan: %.1f s: simulating the on-site identification over the next variant's strips and travel\n",
                     elapsed_s());
      else
        std::fprintf(stderr, "plan: %.1f s: variant %d of %d: %s\n", elapsed_s(), n, of, plan::describe(t).c_str());
    };
    search = plan::search_measurable(p, so);
  }
  char b[300];
  std::snprintf(b, sizeof b,
                "the deadline of %g s passed after %.1f s: the test was evaluated, variants marked NOT EVALUATED "
                "were not (--deadline)",
                o.deadline_s, elapsed_s());
  const std::string deadline_note = b;
  if (o.json) {
    nlohmann::json j = {{"format", "eical-plan/1"}, {"prediction", prediction_json(r)}};
    j["nearest_measurable"] = search.found ? prediction_json(*search.found) : nlohmann::json(nullptr);
    j["variants"] = search_json(search);
    j["deadline_passed"] = search.deadline_passed;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::string text = prediction_text(r);
    if (!r.measurable) {
      if (search.found)
        text += "\nnearest measurable variant:\n" + prediction_text(*search.found);
      else if (!search.deadline_passed)
        text += "\nno variant within " + std::to_string(static_cast<int>(o.max_s)) + " s is measurable; tried:\n" +
                search_text(search);
      else
        text += "\nno measurable variant found before the deadline; variants:\n" + search_text(search);
    }
    std::fputs(text.c_str(), stdout);
  }
  if (!o.layout_svg.empty()) {
    const plan::TestProgram& shown = r.measurable || !search.found ? r.program : search.found->program;
    write_file_atomic(o.layout_svg, plan::layout_svg(shown));
  }
  if (search.deadline_passed) {
    std::fprintf(stderr, "plan: %s\n", deadline_note.c_str());
    throw CLI::RuntimeError(kExitIncomplete);
  }
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
