#pragma once
// A Record as JSON: the spool's file format (eical-history-spool/1) and `eical history show
// --json`. The stored document is embedded as a JSON object, not as a string.
#include "history/record/record.hpp"

#include <nlohmann/json.hpp>

namespace eical::history {

nlohmann::json record_json(const Record& r);
// Throws std::invalid_argument naming the missing or mistyped field.
Record record_from_json(const nlohmann::json& j);

nlohmann::json summary_json(const Summary& s);

}  // namespace eical::history
