// eical-result/1 keys (docs/result-format.md) for every program kind: simulated runs of
// each kind analysed, the JSON document printed, parsed back and checked key by key —
// names, units in the names, numbers or null, and a reason in quality.flags for each null.
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/key_unit.hpp"
#include "sim/simulate.hpp"
#include "tools/sim_programs.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <set>

namespace eical {
namespace {

using nlohmann::json;

// results.md, object by object.
const std::map<std::string, std::vector<std::string>> kSpecKeys = {
    {"circle",
     {"plane", "radius_nominal_mm", "feed_mm_min", "radius_mean_deviation_um", "circular_deviation_G_um",
      "circular_hysteresis_H_um", "radial_deviation_F_max_um", "radial_deviation_F_min_um", "trace"}},
    {"diagnostics",
     {"backlash_x_um", "backlash_y_um", "reversal_spike_x_um", "reversal_spike_y_um", "lateral_play_x_um",
      "lateral_play_y_um", "cyclic_error_x_um", "cyclic_error_y_um", "servo_mismatch_ms", "squareness_urad",
      "scale_mismatch_ppm", "straightness_x_um", "straightness_y_um", "stick_slip_um", "vibration_um"}},
    {"positioning",
     {"axis", "targets_mm", "runs", "A_um", "A_up_um", "A_down_um", "E_um", "M_um", "R_um", "R_up_um", "R_down_um",
      "B_um", "B_mean_um", "deviation_um"}},
    {"step", {"axis", "end_position_error_um", "scatter_um", "overshoot_um", "settling_s"}},
    {"rectangle", {"corners_mm", "corner_errors_um"}},
};

// Which objects each program kind must carry.
const std::map<std::string, std::vector<std::string>> kObjectsOfKind = {
    {"circle", {"circle", "diagnostics"}}, {"positioning", {"positioning"}}, {"step", {"step"}},
    {"rectangle", {"rectangle"}},          {"freeform", {"freeform"}},
};

// A number-valued key must say its unit (a suffix of dsp/core/key_unit.hpp's table), or be a count.
bool has_unit(const std::string& key) {
  return !dsp::unit_of_key(key).empty() || key == "runs" || key == "revolutions";
}

// By code and figure, as a program reading the result decides (result-format.md).
bool flag_explains(const json& doc, const std::string& object, const std::string& key) {
  const json& q = doc["quality"];
  for (std::size_t i = 0; i < q["flag_codes"].size(); ++i) {
    const std::string code = q["flag_codes"][i].get<std::string>(), figure = q["flag_figures"][i].get<std::string>();
    if (figure == object + "." + key) return true;
    if (figure == object && (code == "figure_null" || code == "evaluation_failed")) return true;
  }
  return false;
}

// Settings and choices among candidates: numbers that are not figures (no uncertainty).
bool is_setting(const std::string& key) {
  for (const char* k : {"radius_nominal_mm", "feed_mm_min", "arc_deg", "arc_start_deg", "revolutions", "runs",
                        "cyclic_pitch_mm", "smallest_step_resolved_um", "path_length_mm"})
    if (key == k) return true;
  return false;
}

// Every numeric figure of the program's objects has its expanded uncertainty, keyed
// <object>.<key> (results.md), a number — or null with the reason in uncertainty.method.
void check_uncertainty(const json& doc, const std::string& obj, const json& o, const std::string& prefix) {
  for (const auto& [key, value] : o.items()) {
    if (value.is_object() && key != "trace") check_uncertainty(doc, obj, value, prefix + key + ".");
    if (!value.is_number() || is_setting(key)) continue;
    const std::string k = obj + "." + prefix + key;
    ASSERT_TRUE(doc["uncertainty_k2"].contains(k)) << k << " has no uncertainty_k2 entry";
    EXPECT_TRUE(doc["uncertainty_k2"][k].is_number()) << k << ": " << doc["uncertainty_k2"][k].dump();
    if (doc["uncertainty_k2"][k].is_number()) {
      EXPECT_GE(doc["uncertainty_k2"][k].get<double>(), 0.0) << k;
    }
  }
}

void check_document(const json& doc, const std::string& kind) {
  SCOPED_TRACE(kind);
  const std::string verdict = doc.at("quality").at("verdict").get<std::string>();
  EXPECT_TRUE(verdict == "ok" || verdict == "degraded" || verdict == "not_measurable") << verdict;
  EXPECT_TRUE(doc.at("quality").at("verdict_reasons").is_array());
  EXPECT_EQ(doc.at("quality").at("flag_severity").size(), doc.at("quality").at("flags").size());
  EXPECT_EQ(doc.at("quality").at("flag_codes").size(), doc.at("quality").at("flags").size());
  EXPECT_EQ(doc.at("quality").at("flag_figures").size(), doc.at("quality").at("flags").size());
  ASSERT_TRUE(doc.at("uncertainty_k2").is_object());
  EXPECT_EQ(doc.at("uncertainty").at("coverage_factor"), 2);
  EXPECT_EQ(doc.at("format"), "eical-result/1");
  EXPECT_TRUE(doc.at("run_id").is_string());
  EXPECT_EQ(doc.at("program"), kind);
  EXPECT_TRUE(doc.at("quality").at("degraded").is_boolean());
  EXPECT_TRUE(doc.at("quality").at("flags").is_array());
  EXPECT_TRUE(doc.at("sensor_model").at("identified").is_boolean());
  EXPECT_TRUE(doc.at("sensor_model").at("source").is_string());
  for (const auto& obj : kObjectsOfKind.at(kind)) {
    ASSERT_TRUE(doc.contains(obj) && doc[obj].is_object()) << "missing object " << obj << " for " << kind;
    const json& o = doc[obj];
    if (kSpecKeys.count(obj)) {
      for (const auto& key : kSpecKeys.at(obj)) {
        EXPECT_TRUE(o.contains(key)) << obj << "." << key << " missing";
      }
    }
    if (obj != "freeform" || !o.value("contour_error_max_um", json()).is_null()) check_uncertainty(doc, obj, o, "");
    for (const auto& [key, value] : o.items()) {
      if (value.is_number()) {
        EXPECT_TRUE(has_unit(key)) << obj << "." << key << " is a number without a unit in its name";
      }
      if (value.is_null()) {
        EXPECT_TRUE(flag_explains(doc, obj, key)) << obj << "." << key << " is null without a reason";
      }
    }
  }
}

json analysed(const sim::Scenario& sc) {
  const dsp::Run run = sim::simulate(sc);
  // Through text, as a consumer of `eical analyze --json` reads it.
  return json::parse(drivers::result_json(run, dsp::analyze_run(run)).dump(2));
}

TEST(ResultKeys, CircleBothDirections) {
  const json doc = analysed(sim::circle_scenario(10.0, 2500.0, 1, "both"));
  check_document(doc, "circle");
  EXPECT_TRUE(doc["circle"]["circular_hysteresis_H_um"].is_number());
  EXPECT_TRUE(doc["diagnostics"]["servo_mismatch_ms"].is_number());
  EXPECT_EQ(doc["circle"]["trace"]["angle_deg"].size(), doc["circle"]["trace"]["radius_deviation_um"].size());
  EXPECT_EQ(doc["circle"]["trace"]["angle_deg"].size(), doc["circle"]["trace"]["direction"].size());
  std::set<std::string> dirs;
  for (const auto& d : doc["circle"]["trace"]["direction"]) dirs.insert(d.get<std::string>());
  EXPECT_EQ(dirs, (std::set<std::string>{"ccw", "cw"}));
}

TEST(ResultKeys, CircleOneDirectionHasNullHysteresisWithAReason) {
  const json doc = analysed(sim::circle_scenario(10.0, 2500.0, 1, "ccw"));
  check_document(doc, "circle");
  EXPECT_TRUE(doc["circle"]["circular_hysteresis_H_um"].is_null());
  EXPECT_TRUE(doc["diagnostics"]["servo_mismatch_ms"].is_null());
}

TEST(ResultKeys, PartialArcCarriesTheArcAndNullDiagnostics) {
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 1, "both");
  sc.meta.program.arc_deg = 220.0;
  sc.meta.program.plane = "zx";
  const json doc = analysed(sc);
  check_document(doc, "circle");
  EXPECT_EQ(doc["circle"]["arc_deg"], 220.0);
  EXPECT_EQ(doc["circle"]["plane"], "zx");
  EXPECT_TRUE(doc["circle"]["circular_deviation_G_um"].is_number());
  EXPECT_TRUE(doc["diagnostics"]["backlash_x_um"].is_null());
}

TEST(ResultKeys, Positioning) {
  const json doc = analysed(sim::positioning_scenario({0.0, 10.0, 20.0}, 2));
  check_document(doc, "positioning");
  EXPECT_EQ(doc["positioning"]["deviation_um"]["up"].size(), 2u);
  // Fewer than 5 runs: evaluated, and said to be outside ISO 230-2.
  EXPECT_FALSE(doc["positioning"]["within_standard"].get<bool>());
  bool flagged = false;
  for (std::size_t i = 0; i < doc["quality"]["flag_codes"].size(); ++i)
    flagged |=
        doc["quality"]["flag_codes"][i] == "outside_standard" && doc["quality"]["flag_figures"][i] == "positioning";
  EXPECT_TRUE(flagged);
  EXPECT_EQ(doc["uncertainty_k2"]["positioning.per_target.mean_um"].size(), 3u);
  EXPECT_EQ(doc["positioning"]["deviation_um"]["up"][0].size(), 3u);
}

TEST(ResultKeys, Step) {
  const json doc = analysed(sim::step_scenario(0.0, 20.0, 3250.0, 2));
  check_document(doc, "step");
  EXPECT_TRUE(doc["step"]["end_position_error_um"].is_number());
}

TEST(ResultKeys, Rectangle) {
  const json doc = analysed(sim::rectangle_scenario(20.0, 10.0, 1500.0, "xy", 1, 1));
  check_document(doc, "rectangle");
  ASSERT_EQ(doc["rectangle"]["corners_mm"].size(), 4u);  // 4 corners, one lap
  ASSERT_EQ(doc["rectangle"]["corner_errors_um"].size(), 4u);
  // Second stop: (x1, y1) of the 20 × 10 mm rectangle from the origin (set-point to ~1 nm).
  EXPECT_NEAR(doc["rectangle"]["corners_mm"][1][0].get<double>(), 20.0, 1e-6);
  EXPECT_NEAR(doc["rectangle"]["corners_mm"][1][1].get<double>(), 10.0, 1e-6);
  EXPECT_TRUE(doc["rectangle"]["path_deviation"]["contour_error_max_um"].is_number());
  // Arrays keep their figure's shape in uncertainty_k2: a pair per corner.
  ASSERT_EQ(doc["uncertainty_k2"]["rectangle.corner_errors_um"].size(), 4u);
  EXPECT_EQ(doc["uncertainty_k2"]["rectangle.corner_errors_um"][0].size(), 2u);
}

TEST(ResultKeys, FreeForm) {
  const json doc = analysed(tools::freeform_scenario(1500.0, 1));
  check_document(doc, "freeform");
  EXPECT_TRUE(doc["freeform"]["contour_error_max_um"].is_number());
  EXPECT_GT(doc["freeform"]["trace"]["normal_um"].size(), 100u);
}

// The real binary: `eical analyze RUN --json` prints the same document.
TEST(ResultKeys, AnalyzeCommandPrintsTheDocument) {
  const auto dir = std::filesystem::temp_directory_path() / ("result-keys-" + std::to_string(std::random_device{}()));
  drivers::write_run(sim::simulate(sim::step_scenario(0.0, 20.0, 3250.0, 1)), dir / "run", {});
  FILE* p = popen((std::string(EICAL_CLI) + " analyze " + (dir / "run").string() + " --json").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  const json doc = json::parse(out);
  check_document(doc, "step");
  // The exit status is the verdict's (docs/command-line.md, "Exit status").
  const std::string verdict = doc["quality"]["verdict"];
  EXPECT_EQ(WEXITSTATUS(status), verdict == "ok" ? 0 : verdict == "degraded" ? 2 : 3) << verdict;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace eical
