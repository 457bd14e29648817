#pragma once
// What `eical comp` reads: eical-result/1 documents (results.md), given as a JSON file
// (`eical analyze RUN --json`) or as a run directory (its result.json, written by eicald
// or `eical analyze`, else the run is analysed now), and the figures in them with their
// expanded uncertainty (uncertainty_k2, keyed "<section>.<key>").
#include "dsp/core/run_meta.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace eical::tools::comp {

struct CompInput {
  std::string name;  // the path as given
  std::string run_id;
  nlohmann::json result;
  std::optional<dsp::Program> program;  // run.toml's [program], for run directories
};

// InputError naming the path when it is neither a run directory nor an eical-result/1 file.
CompInput load_comp_input(const std::string& path);

// A figure of a result and what decides whether compensation may be built on it:
// resolved when |value| > U (k = 2); a figure without an uncertainty is not resolved.
struct Figure {
  std::string key;    // "<section>.<key>", as in uncertainty_k2
  std::string input;  // where it comes from
  double value = 0.0;
  std::optional<double> u_k2;
  [[nodiscard]] bool resolved() const;
  // "diagnostics.backlash_x_um = 3.9 (U = 0.6, k = 2) in runs/c1" etc.
  [[nodiscard]] std::string describe() const;
  [[nodiscard]] nlohmann::json to_json() const;
};

// The figure `section.key` of an input; InputError naming the input when it is absent or
// null (the result's quality.flags say why).
Figure figure(const CompInput& in, const std::string& key);

// Several figures of one quantity (e.g. the backlash of x from two circles): their mean,
// U = √ΣU²/n, resolved only if every one has an uncertainty.
Figure combined(const std::vector<Figure>& figures);

}  // namespace eical::tools::comp
