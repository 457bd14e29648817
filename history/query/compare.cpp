#include "history/query/compare.hpp"

#include "history/record/result_record.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <map>

namespace eical::history {
namespace {

Summary summary_of(const Record& r) { return {r.machine, r.run_id, r.program, r.measured_at, r.verdict, r.degraded}; }

// The test's set-up in a document: the program parameters and the strings that say what
// was run (plane, axis, direction).
std::map<std::string, std::string> setup_of(const std::string& document) {
  std::map<std::string, std::string> out;
  const auto doc = nlohmann::json::parse(document, nullptr, false);
  if (!doc.is_object()) return out;
  out["program"] = doc.value("program", "");
  for (const auto& [section, obj] : doc.items()) {
    if (!obj.is_object()) continue;
    for (const auto& [key, v] : obj.items()) {
      const std::string name = section + "." + key;
      if ((v.is_number() && is_program_parameter(name)) ||
          ((key == "plane" || key == "axis" || key == "direction") && v.is_string()))
        out[name] = v.is_string() ? v.get<std::string>() : v.dump();
    }
  }
  return out;
}

}  // namespace

const char* judgement_name(Judgement j) {
  switch (j) {
    case Judgement::significant: return "significant";
    case Judgement::within_uncertainty: return "within_uncertainty";
    case Judgement::not_judged: return "not_judged";
    case Judgement::missing: return "missing";
  }
  return "missing";
}

Comparison compare(const Record& before, const Record& after) {
  Comparison c{summary_of(before), summary_of(after), {}, {}};
  std::map<std::string, FigureChange> by_name;
  for (const auto& f : before.figures) {
    auto& fc = by_name[f.name];
    fc.name = f.name, fc.before = f.value, fc.u_before = f.uncertainty_k2;
  }
  for (const auto& f : after.figures) {
    auto& fc = by_name[f.name];
    fc.name = f.name, fc.after = f.value, fc.u_after = f.uncertainty_k2;
  }
  for (auto& [name, fc] : by_name) {
    if (!fc.before || !fc.after) {
      fc.judgement = Judgement::missing;
    } else {
      fc.difference = *fc.after - *fc.before;
      if (fc.u_before && fc.u_after) {
        fc.uncertainty_k2 = std::hypot(*fc.u_before, *fc.u_after);
        fc.judgement =
            std::abs(*fc.difference) > *fc.uncertainty_k2 ? Judgement::significant : Judgement::within_uncertainty;
      } else {
        fc.judgement = Judgement::not_judged;
      }
    }
    c.figures.push_back(fc);
  }
  const auto a = setup_of(before.document), b = setup_of(after.document);
  for (const auto& [k, v] : a)
    if (auto it = b.find(k); it != b.end() && it->second != v)
      c.not_comparable.push_back(k + ": " + v + " → " + it->second);
  if (before.machine != after.machine) c.not_comparable.push_back("machine: " + before.machine + " → " + after.machine);
  return c;
}

}  // namespace eical::history
