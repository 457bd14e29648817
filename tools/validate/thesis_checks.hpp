#pragma once
// The simulator against the numbers the thesis measured and simulated (shared/seeds/000,
// ch. 3, 6, 7, 8; docs/physics.md). Each check simulates what the thesis
// describes, runs eical's own pipeline or the closed form on it, and reports the figure
// beside the thesis' one. `eical validate-sim` prints the table; a test asserts the
// tolerances.
#include <string>
#include <vector>

namespace eical::tools {

struct ThesisCheck {
  std::string name;    // what is compared
  std::string source;  // where the thesis figure comes from
  std::string unit;
  double thesis = 0.0;  // the thesis' figure (or the closed form it gives)
  double simulated = 0.0;
  double ratio_min = 0.0, ratio_max = 0.0;  // accepted simulated/thesis
  std::string how;                          // how the simulated figure was obtained
  [[nodiscard]] double ratio() const { return simulated / thesis; }
  [[nodiscard]] bool within() const { return ratio() >= ratio_min && ratio() <= ratio_max; }
};

struct ValidationOptions {
  int monte_carlo_windows = 400;  // 1.2 s windows per noise check (σ to ~3.5 %)
  std::uint64_t seed = 1;
};

std::vector<ThesisCheck> validate_against_thesis(const ValidationOptions& options = {});

}  // namespace eical::tools
