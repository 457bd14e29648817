#include "tools/plan/plan_check.hpp"

#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/figures_on_path.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "sim/simulate.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace eical::tools::plan {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::vector<TestProgram> check_programs(bool identified) {
  std::vector<TestProgram> out;
  TestProgram c;
  c.kind = dsp::ProgramKind::circle, c.radius_mm = 10.0, c.feed_mm_min = 2500.0, c.repeats = 5;
  c.psd = strips_for(c);
  out.push_back(c);
  TestProgram s;
  s.kind = dsp::ProgramKind::step, s.from_mm = 0.0, s.to_mm = 50.0, s.feed_mm_min = 6500.0, s.runs = 3;
  s.psd = strips_for(s);
  out.push_back(s);
  TestProgram p;
  p.kind = dsp::ProgramKind::positioning, p.targets_mm = {0.0, 10.0, 20.0, 30.0}, p.runs = 3, p.feed_mm_min = 3000.0;
  p.psd = strips_for(p);
  out.push_back(p);
  TestProgram r;
  r.kind = dsp::ProgramKind::rectangle, r.size_mm[0] = 40.0, r.size_mm[1] = 30.0, r.feed_mm_min = 4000.0, r.repeats = 1;
  r.psd = strips_for(r);
  out.push_back(r);
  for (auto& t : out) t.identified = identified;
  return out;
}

std::vector<CheckRow> check_plan(const TestProgram& p, int repeats, int draws) {
  const Prediction pred = predict(p, 1, draws);
  const dsp::ResolutionLimit* lim = dsp::resolution_limit(p.kind);
  std::vector<std::string> keys{lim->limited};
  if (p.kind == dsp::ProgramKind::circle) keys.emplace_back("circle.radius_mean_deviation_um");
  if (p.kind == dsp::ProgramKind::positioning) keys.emplace_back("positioning.M_um");
  std::vector<std::vector<double>> errors(keys.size());
  int degraded = 0;
  for (int r = 0; r < repeats; ++r) {
    const std::uint64_t seed = 1000 + static_cast<std::uint64_t>(r);
    const sim::Scenario sc = scenario_on_drawn_machine(p, seed);
    std::vector<Eigen::Vector3d> truth;
    dsp::Run run = sim::simulate(sc, &truth);
    dsp::AnalysisOptions o;
    o.coriolis = sc.coriolis;
    if (p.identified) {  // this machine's sensors identified on site first
      const sim::Scenario id = identification_on_machine(p, sc, seed);
      dsp::identify::apply_identification(dsp::identify::identify_sensors(sim::simulate(id)), run.meta);
      o.sensor_model = "psd";
    }
    o.uncertainty.enabled = false;  // only the figures: their spread is the point
    const dsp::Analysis a = dsp::analyze_run(run, o);
    // A degraded run (the strips disagreeing with the data sheet's sensors, say) is flagged
    // and carries its own, larger U; the plan predicts the run that is not degraded.
    if (a.degraded) {
      ++degraded;
      continue;
    }
    const auto measured = dsp::figures_of(a), true_figs = dsp::figures_on_path(run, truth, a);
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const auto* m = dsp::find_figure(measured, keys[k]);
      const auto* t = dsp::find_figure(true_figs, keys[k]);
      if (m && t && !m->values.empty() && m->values.size() == t->values.size())
        errors[k].push_back(m->values[0] - t->values[0]);
    }
  }
  std::vector<CheckRow> rows;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    CheckRow row;
    row.program = describe(p), row.key = keys[k];
    const auto it = pred.u_k2.find(keys[k]);
    row.predicted_u = it != pred.u_k2.end() ? it->second : kNaN;
    const auto& e = errors[k];
    row.repeats = static_cast<int>(e.size());
    row.degraded = degraded;
    double sum = 0.0, ss = 0.0;
    for (double x : e) sum += x;
    row.mean_error = e.empty() ? kNaN : sum / static_cast<double>(e.size());
    for (double x : e) ss += (x - row.mean_error) * (x - row.mean_error);
    row.sd_error = e.size() > 1 ? std::sqrt(ss / static_cast<double>(e.size() - 1)) : kNaN;
    row.empirical_u = std::abs(row.mean_error) + 2.0 * row.sd_error;
    rows.push_back(row);
  }
  return rows;
}

std::string check_table(const std::vector<CheckRow>& rows) {
  std::string o;
  char b[320];
  std::snprintf(b, sizeof b, "  %-58s %-34s %9s %9s %7s %9s %9s %8s\n", "program", "figure", "U plan", "U sim", "ratio",
                "mean err", "sd err", "repeats");
  o += b;
  for (const auto& r : rows) {
    std::snprintf(b, sizeof b, "  %-58s %-34s %9.3f %9.3f %7.2f %9.3f %9.3f %4d (+%d)%s\n",
                  r.program.substr(0, 58).c_str(), r.key.c_str(), r.predicted_u, r.empirical_u, r.ratio(), r.mean_error,
                  r.sd_error, r.repeats, r.degraded, std::abs(r.ratio() - 1.0) <= 0.3 ? "" : "  OUT");
    o += b;
  }
  o += "  (U plan: predicted before the test; U sim: |mean error| + 2 sd over the repeats against the truth; within 30 "
       "% is the target;\n"
       "   repeats: runs compared (+ degraded runs left out: the strips disagreed with the data sheet's sensors, "
       "flagged, with their own U))\n";
  return o;
}

}  // namespace eical::tools::plan
