#include "history/record/result_record.hpp"

#include "dsp/core/key_unit.hpp"
#include "history/record/figure_names.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

namespace eical::history {
namespace {

// Top-level objects that are not program sections: the quality, the uncertainty map
// itself, the sensor model and the pipeline's bookkeeping (counts, windows).
// uncertainty_k2, noise_bound_k2 and uncertainty_budget_k2 describe the figures (their U,
// the test's bound, the budget); uncertainty holds how U was computed.
constexpr std::array<const char*, 7> kNotSections = {
    "quality", "uncertainty_k2", "noise_bound_k2", "uncertainty_budget_k2", "uncertainty", "sensor_model", "pipeline"};

// What the program was asked to do, not what was measured: not a figure of the history.
constexpr std::array<const char*, 6> kProgramParameters = {"circle.radius_nominal_mm", "circle.feed_mm_min",
                                                           "circle.revolutions",       "circle.arc_deg",
                                                           "circle.arc_start_deg",     "positioning.runs"};

bool is_section(const std::string& key) {
  return std::none_of(kNotSections.begin(), kNotSections.end(), [&](const char* s) { return key == s; });
}

// A member is a figure when it is a number, or null with a unit in its name (a figure
// the evaluation could not determine; other nulls are absent objects).
void collect(const nlohmann::json& obj, const std::string& prefix, std::map<std::string, Figure>& out, int depth) {
  for (const auto& [key, v] : obj.items()) {
    const std::string name = prefix + key;
    if (v.is_number()) {
      const double x = v.get<double>();
      out[name] = {name, std::isfinite(x) ? std::optional<double>(x) : std::nullopt, std::nullopt};
    } else if (v.is_null() && !dsp::unit_of_key(name).empty()) {
      out[name] = {name, std::nullopt, std::nullopt};
    } else if (v.is_object() && depth == 0 && key != "trace") {
      collect(v, name + ".", out, depth + 1);
    }
  }
}

const nlohmann::json* at_path(const nlohmann::json& doc, const std::string& dotted) {
  const nlohmann::json* j = &doc;
  std::size_t start = 0;
  while (start <= dotted.size()) {
    const std::size_t end = std::min(dotted.find('.', start), dotted.size());
    const std::string key = dotted.substr(start, end - start);
    if (!j->is_object() || !j->contains(key)) return nullptr;
    j = &(*j)[key];
    start = end + 1;
  }
  return j;
}

// Every array of a "trace" object (parallel arrays: angle, deviation, direction, ...)
// thinned by one stride to at most kStoredTracePoints; the stride is noted beside them.
void thin_traces(nlohmann::json& j) {
  if (!j.is_object()) return;
  for (auto& [key, v] : j.items()) {
    if (key == "trace" && v.is_object()) {
      std::size_t n = 0;
      for (const auto& [k, arr] : v.items())
        if (arr.is_array()) n = std::max(n, arr.size());
      if (n <= kStoredTracePoints) continue;
      const std::size_t stride = (n + kStoredTracePoints - 1) / kStoredTracePoints;
      for (auto& [k, arr] : v.items()) {
        if (!arr.is_array()) continue;
        nlohmann::json thin = nlohmann::json::array();
        for (std::size_t i = 0; i < arr.size(); i += stride) thin.push_back(arr[i]);
        arr = std::move(thin);
      }
      v["stored_every"] = stride;
    } else {
      thin_traces(v);
    }
  }
}

}  // namespace

bool is_program_parameter(const std::string& figure) {
  return std::any_of(kProgramParameters.begin(), kProgramParameters.end(), [&](const char* p) { return figure == p; });
}

std::vector<Figure> figures_of(const nlohmann::json& doc) {
  std::map<std::string, Figure> found;
  for (const auto& [key, v] : doc.items())
    if (v.is_object() && is_section(key)) collect(v, key + ".", found, 0);
  // Every key the uncertainty map names is a figure, wherever it sits in the document.
  const auto u = doc.find("uncertainty_k2");
  if (u != doc.end() && u->is_object()) {
    for (const auto& [name, uk2] : u->items()) {
      if (!found.count(name))
        if (const auto* v = at_path(doc, name); v && (v->is_number() || v->is_null()))
          found[name] = {name, v->is_number() ? std::optional<double>(v->get<double>()) : std::nullopt, std::nullopt};
      if (auto it = found.find(name); it != found.end() && uk2.is_number() && std::isfinite(uk2.get<double>()))
        it->second.uncertainty_k2 = uk2.get<double>();
    }
  }
  std::vector<Figure> out;
  for (auto& [name, f] : found)
    if (!is_program_parameter(name)) out.push_back(std::move(f));
  return out;  // std::map: sorted by name
}

Record record_from_result(const nlohmann::json& doc, const Provenance& p) {
  if (!doc.is_object() || doc.value("format", "") != "eical-result/1")
    throw std::invalid_argument("not an eical-result/1 document (format)");
  if (!doc.contains("run_id") || !doc["run_id"].is_string() || doc["run_id"].get<std::string>().empty())
    throw std::invalid_argument("eical-result/1 document without run_id");
  if (p.machine.empty())
    throw std::invalid_argument("result " + doc["run_id"].get<std::string>() + ": no machine name");
  Record r;
  r.machine = p.machine;
  r.run_id = doc["run_id"].get<std::string>();
  r.program = doc.value("program", "");
  r.measured_at = utc_rfc3339(p.measured_at);
  if (r.measured_at.empty())
    throw std::invalid_argument("result " + r.run_id + ": measurement time '" + p.measured_at +
                                "' is not an RFC 3339 date-time");
  const auto q = doc.find("quality");
  if (q != doc.end() && q->is_object()) {
    if (q->contains("verdict") && (*q)["verdict"].is_string()) r.verdict = (*q)["verdict"].get<std::string>();
    r.degraded = q->value("degraded", false);
  }
  r.run_path = p.run_path;
  r.software_version = p.software_version;
  if (!r.software_version && doc.contains("software") && doc["software"].is_string())
    r.software_version = doc["software"].get<std::string>();
  r.sensor_calibration = p.sensor_calibration;
  if (r.sensor_calibration.empty()) {
    const auto sm = doc.find("sensor_model");
    r.sensor_calibration = sm != doc.end() && sm->is_object() ? sm->value("source", "datasheet") : "datasheet";
  }
  r.figures = figures_of(doc);
  nlohmann::json stored = doc;
  thin_traces(stored);
  r.document = stored.dump();
  return r;
}

}  // namespace eical::history
