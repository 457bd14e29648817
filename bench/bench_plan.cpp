// eical plan against simulation (issue 16): per program the predicted U of its headline
// figures beside the spread of the figures over repeats on machines drawn within the data
// sheet's tolerances (tools/plan/plan_check.hpp).
//   bench_plan [--repeats 20] [--draws 100] [--programs circle,...] [--datasheet]
//              [--circle R,F,PSD ...]   a circle of its own, both directions x2 (e.g. 50,4000,R16;
//                                       PSD as eical plan --psd takes it)
#include "tools/plan/plan_check.hpp"
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/plan/psd_layouts.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>

int main(int argc, char** argv) {
  CLI::App app("eical plan-vs-simulation benchmark");
  int repeats = 20, draws = 100;
  std::vector<std::string> only;
  std::vector<std::vector<std::string>> circles;
  bool datasheet = false;
  app.add_option("--repeats", repeats, "simulated repeats per program");
  app.add_option("--draws", draws, "Monte Carlo draws of the prediction");
  app.add_option("--programs", only, "circle, step, positioning, rectangle (default: all)")->delimiter(',');
  app.add_flag("--datasheet", datasheet, "the data sheet's sensor model instead of an identification before each test");
  app.add_option("--circle", circles,
                 "instead of the programs: a circle RADIUS,FEED,PSD (repeatable; PSD e.g. B16, R16)")
      ->delimiter(',')
      ->expected(3)
      ->allow_extra_args(false);
  CLI11_PARSE(app, argc, argv);
  std::vector<eical::tools::plan::TestProgram> programs = eical::tools::plan::check_programs(!datasheet);
  if (!circles.empty()) programs.clear();
  for (const auto& c : circles) {
    eical::tools::plan::TestProgram p;
    p.kind = eical::dsp::ProgramKind::circle, p.direction = "both", p.repeats = 2, p.identified = !datasheet;
    try {
      p.radius_mm = std::stod(c.at(0)), p.feed_mm_min = std::stod(c.at(1));
      const auto layout = eical::tools::plan::psd_layout(c.at(2));
      p.psd = eical::tools::plan::strips_for(p, layout.strips, layout.facing);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_plan --circle %s,%s,%s: %s\n", c.at(0).c_str(), c.at(1).c_str(), c.at(2).c_str(),
                   e.what());
      return 1;
    }
    programs.push_back(p);
  }
  std::vector<eical::tools::plan::CheckRow> rows;
  for (const auto& p : programs) {
    if (!only.empty() && std::find(only.begin(), only.end(), eical::dsp::program_kind_name(p.kind)) == only.end())
      continue;
    const auto r = eical::tools::plan::check_plan(p, repeats, draws);
    rows.insert(rows.end(), r.begin(), r.end());
    std::fputs(eical::tools::plan::check_table(r).c_str(), stdout);
    std::fflush(stdout);
  }
  std::printf("\nall programs, %d repeats each:\n%s", repeats, eical::tools::plan::check_table(rows).c_str());
  return 0;
}
