#include "history/record/record_json.hpp"

#include <stdexcept>

namespace eical::history {
namespace {

nlohmann::json opt(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }
nlohmann::json opt(const std::optional<std::string>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

std::string text(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_string())
    throw std::invalid_argument(std::string("record: '") + key + "' missing or not a string");
  return j[key].get<std::string>();
}

std::optional<std::string> opt_text(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  return text(j, key);
}

std::optional<double> opt_number(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  if (!j[key].is_number()) throw std::invalid_argument(std::string("record: figure '") + key + "' is not a number");
  return j[key].get<double>();
}

}  // namespace

nlohmann::json summary_json(const Summary& s) {
  return {{"machine", s.machine},         {"run_id", s.run_id},        {"program", s.program},
          {"measured_at", s.measured_at}, {"verdict", opt(s.verdict)}, {"degraded", s.degraded}};
}

nlohmann::json record_json(const Record& r) {
  nlohmann::json figures = nlohmann::json::array();
  for (const auto& f : r.figures)
    figures.push_back({{"name", f.name}, {"value", opt(f.value)}, {"uncertainty_k2", opt(f.uncertainty_k2)}});
  nlohmann::json doc = r.document.empty() ? nlohmann::json(nullptr) : nlohmann::json::parse(r.document, nullptr, false);
  return {{"machine", r.machine},
          {"run_id", r.run_id},
          {"program", r.program},
          {"measured_at", r.measured_at},
          {"verdict", opt(r.verdict)},
          {"degraded", r.degraded},
          {"run_path", r.run_path},
          {"software_version", opt(r.software_version)},
          {"sensor_calibration", r.sensor_calibration},
          {"figures", figures},
          {"document", doc}};
}

Record record_from_json(const nlohmann::json& j) {
  if (!j.is_object()) throw std::invalid_argument("record: not a JSON object");
  Record r;
  r.machine = text(j, "machine");
  r.run_id = text(j, "run_id");
  r.program = text(j, "program");
  r.measured_at = text(j, "measured_at");
  r.verdict = opt_text(j, "verdict");
  if (!j.contains("degraded") || !j["degraded"].is_boolean())
    throw std::invalid_argument("record: 'degraded' missing or not a boolean");
  r.degraded = j["degraded"].get<bool>();
  r.run_path = text(j, "run_path");
  r.software_version = opt_text(j, "software_version");
  r.sensor_calibration = text(j, "sensor_calibration");
  if (!j.contains("figures") || !j["figures"].is_array())
    throw std::invalid_argument("record: 'figures' missing or not an array");
  for (const auto& f : j["figures"]) {
    if (!f.is_object()) throw std::invalid_argument("record: a figure is not an object");
    r.figures.push_back({text(f, "name"), opt_number(f, "value"), opt_number(f, "uncertainty_k2")});
  }
  if (!j.contains("document") || !j["document"].is_object())
    throw std::invalid_argument("record: 'document' missing or not an object");
  r.document = j["document"].dump();
  return r;
}

}  // namespace eical::history
