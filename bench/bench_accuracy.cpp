// Accuracy benchmark (issue 4): sensors off their data sheet, identified on site from the
// PSD strips and the set-point only, then the thesis' circle, 1-D move and rectangle
// against the simulator's truth; every figure beside its noise-limited bound
// (tests/support/accuracy_campaign.hpp says how the bound is derived).
//   bench_accuracy [--seeds 1,2,3] [--datasheet]
#include "tests/support/accuracy_campaign.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  CLI::App app("eical accuracy benchmark");
  std::vector<std::uint64_t> seeds{1, 2, 3};
  bool datasheet = false, oracle = false;
  app.add_option("--seeds", seeds, "machines to draw (each its own sensor deviations)")->delimiter(',');
  app.add_flag("--datasheet", datasheet, "also analyse with the data sheet, uncalibrated");
  app.add_flag("--oracle", oracle, "also analyse with the true sensor parameters (a perfect identification)");
  CLI11_PARSE(app, argc, argv);
  for (const auto seed : seeds) {
    eical::tools::accuracy::Options o;
    o.seed = seed;
    std::fputs(eical::tools::accuracy::table(eical::tools::accuracy::run(o)).c_str(), stdout);
    if (oracle) {
      o.oracle = true;
      std::fputs(eical::tools::accuracy::table(eical::tools::accuracy::run(o)).c_str(), stdout);
      o.oracle = false;
    }
    if (datasheet) {
      o.calibrate = false;
      std::fputs(eical::tools::accuracy::table(eical::tools::accuracy::run(o)).c_str(), stdout);
    }
    std::fflush(stdout);
  }
  return 0;
}
