#pragma once
// One result as the history keeps it: who measured what when (provenance), every numeric
// figure of the eical-result/1 document with its expanded uncertainty, and the document.
#include <optional>
#include <string>
#include <vector>

namespace eical::history {

struct Figure {
  std::string name;                      // "<section>.<key>", e.g. "diagnostics.backlash_x_um"
  std::optional<double> value;           // nullopt: null in the result (could not be determined)
  std::optional<double> uncertainty_k2;  // nullopt: the result gives no uncertainty for it
};

struct Record {
  std::string machine;  // [machine] name
  std::string run_id;
  std::string program;                          // circle, step, positioning, rectangle, freeform
  std::string measured_at;                      // RFC 3339 UTC, "2026-11-12T09:11:00Z"
  std::optional<std::string> verdict;           // quality.verdict; nullopt for results without one
  bool degraded = false;                        // quality.degraded
  std::string run_path;                         // the run directory (on the PC that measured)
  std::optional<std::string> software_version;  // "eical 0.1.0"; nullopt when unknown
  std::string sensor_calibration;               // "datasheet" or "<method>: <file> (run <id>)"
  std::vector<Figure> figures;                  // sorted by name
  std::string document;                         // the eical-result/1 JSON, plot traces thinned

  [[nodiscard]] const Figure* figure(const std::string& name) const;
};

// The row of a listing: a result without its figures and document.
struct Summary {
  std::string machine, run_id, program, measured_at;
  std::optional<std::string> verdict;
  bool degraded = false;
};

}  // namespace eical::history
