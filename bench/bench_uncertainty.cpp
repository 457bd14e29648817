// Uncertainty benchmark (issue 16): a seeded campaign of simulated runs across programs on
// machines within the data sheet's tolerances; prints per figure how often the error
// against the simulator's truth lies within the expanded uncertainty U, the median U and
// the RMS error (tests/support/coverage_campaign.hpp).
//   bench_uncertainty [--seeds 1,2,...] [--draws 100] [--programs circle,step,...]
#include "drivers/exec/thread_for.hpp"
#include "tests/support/coverage_campaign.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  CLI::App app("eical uncertainty coverage benchmark");
  eical::coverage::CampaignOptions o;
  o.seeds = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  app.add_option("--seeds", o.seeds, "machines to draw (each its own sensors and errors)")->delimiter(',');
  app.add_option("--programs", o.programs,
                 "circle, circle-identified, circle-strips (4-16 strips, along the path or radial), circle-large, "
                 "step, positioning, positioning-long, positioning-ends, rectangle")
      ->delimiter(',');
  app.add_option("--draws", o.draws, "Monte Carlo draws per run");
  app.add_option("--write-runs", o.write_runs, "write every simulated run into this folder");
  CLI11_PARSE(app, argc, argv);
  o.parallel = eical::drivers::thread_for();
  std::fputs(eical::coverage::coverage_table(eical::coverage::run_campaign(o)).c_str(), stdout);
  return 0;
}
