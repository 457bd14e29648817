// eical explain RUN... [--json] [--report DIR]: what the simulation (data-sheet sensors, an
// ideal machine following its set-point) gets wrong about each run — shown (residuals in
// time and frequency, their correlation with the candidate regressors), named (run-format
// effects, significance by BIC with a held-out guard and a tolerance band), extended (the
// accepted effects become a sensor calibration and a scenario the simulator reproduces the
// run with) and measured (residual RMS before and after, on fitting and held-out data).
#include "drivers/run_io/run_reader.hpp"
#include "dsp/model/explain.hpp"
#include "tools/commands.hpp"
#include "tools/explain/explain_outputs.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

namespace eical::tools {

void register_explain(CLI::App& app) {
  struct Opt {
    std::vector<std::string> runs;
    bool json = false;
    std::string report;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("explain",
                                 "Show, name, extend and measure what the simulation gets wrong about recorded runs");
  cmd->add_option("runs", o->runs, "run directories (eical-run/1)")->required();
  cmd->add_flag("--json", o->json, "print the eical-explain/1 document");
  cmd->add_option(
      "--report", o->report,
      "write the HTML report with residual plots, the fitted calibration and a scenario reproducing the run");
  cmd->callback([o] {
    std::vector<dsp::Run> runs;
    std::vector<dsp::model::RunExplanation> ex;
    for (const auto& path : o->runs) {
      runs.push_back(drivers::read_run(path));
      const auto t0 = std::chrono::steady_clock::now();
      ex.push_back(dsp::model::explain_run(runs.back()));
      ex.back().seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    // Held out across runs: what one run's explanation took into the model, on the others
    // (runs of the same machine: the same sensors and DAQ).
    std::vector<dsp::model::TransferGain> transfers;
    for (std::size_t i = 0; i < runs.size(); ++i)
      for (std::size_t j = 0; j < runs.size(); ++j)
        if (i != j &&
            std::any_of(ex[i].effects.begin(), ex[i].effects.end(), [](const auto& e) { return e.taken_into_model; }))
          transfers.push_back(dsp::model::transfer_gain(runs[j], ex[i]));
    const nlohmann::json doc = explain::explain_json(runs, ex, transfers);
    if (!o->report.empty()) explain::write_explain_report(runs, ex, o->report);
    if (o->json)
      std::printf("%s\n", doc.dump(2).c_str());
    else
      std::fputs(explain::explain_text(ex, transfers).c_str(), stdout);
  });
}

}  // namespace eical::tools
