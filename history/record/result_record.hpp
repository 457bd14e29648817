#pragma once
// An eical-result/1 document (docs/result-format.md) turned into a history Record:
// every numeric figure of its program sections ("<section>.<key>", one level of nested
// objects as "<section>.<object>.<key>", and every key of uncertainty_k2) with its
// uncertainty_k2 when the result gives one, quality.verdict when present (both are NULL
// otherwise: results written before they existed), and the document with its plot traces
// thinned for the store (the run's own result.json keeps them whole).
#include "history/record/record.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace eical::history {

// What the document does not say: where and when it was measured, with what.
struct Provenance {
  std::string machine;
  std::string measured_at;  // RFC 3339, any offset (stored as UTC)
  std::string run_path;
  std::optional<std::string> software_version;  // nullopt: the document's "software" key, if any
  std::string sensor_calibration;               // "": the document's sensor_model.source
};

// At most this many points per trace are kept in the stored document (the polar and
// deviation plots of `eical history compare` are drawn from them).
inline constexpr std::size_t kStoredTracePoints = 720;

// Throws std::invalid_argument naming what is missing (not an eical-result/1, no run_id,
// no machine, a time that is not RFC 3339).
Record record_from_result(const nlohmann::json& doc, const Provenance& p);

// The figures of a document alone (sorted by name).
std::vector<Figure> figures_of(const nlohmann::json& doc);

// Program parameters are numbers of the sections that are not measured figures.
bool is_program_parameter(const std::string& figure);

}  // namespace eical::history
