#include "drivers/results/result_json.hpp"

#include "drivers/results/software_version.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/verdict.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <stdexcept>
#include <utility>

namespace eical::drivers {

void write_result(const dsp::Run& run, const dsp::Analysis& analysis, const std::filesystem::path& file) {
  const std::string text = result_json(run, analysis).dump(2) + "\n";
  write_text_atomic(file, text);
}

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// Per figure, in the figure's shape, the values `by_key` holds for it (U, or the noise bound).
static nlohmann::json per_figure_json(const dsp::Analysis& analysis,
                                      const std::map<std::string, std::vector<double>>& by_key) {
  nlohmann::json u = nlohmann::json::object();
  for (const dsp::FigureValue& f : dsp::figures_of(analysis)) {
    const auto it = by_key.find(f.key);
    const bool have = it != by_key.end() && it->second.size() == f.values.size();
    if (!f.array) {
      u[f.key] = have ? number_or_null(it->second[0]) : nlohmann::json(nullptr);
      continue;
    }
    nlohmann::json arr = nlohmann::json::array();
    for (std::size_t i = 0; i < f.values.size(); i += static_cast<std::size_t>(f.columns)) {
      if (f.columns == 1) {
        arr.push_back(have ? number_or_null(it->second[i]) : nlohmann::json(nullptr));
        continue;
      }
      nlohmann::json row = nlohmann::json::array();
      for (int c = 0; c < f.columns && i + static_cast<std::size_t>(c) < f.values.size(); ++c)
        row.push_back(have ? number_or_null(it->second[i + static_cast<std::size_t>(c)]) : nlohmann::json(nullptr));
      arr.push_back(row);
    }
    u[f.key] = arr;
  }
  return u;
}

nlohmann::json uncertainty_json(const dsp::Analysis& analysis) {
  return per_figure_json(analysis, analysis.uncertainty_k2);
}

nlohmann::json circle_json(const dsp::Program& program, const dsp::eval::CircleResult& c) {
  nlohmann::json j = {
      {"plane", program.plane},
      {"center_mm", {program.center_mm[0], program.center_mm[1]}},  // programmed, in the plane's axes
      {"radius_nominal_mm", program.radius_mm},
      {"feed_mm_min", program.feed_mm_min},
      {"direction", c.direction},
      {"revolutions", c.revolutions},
      {"arc_deg", c.arc_deg},
      {"centre_reference",
       c.arc_deg < 360.0 ? "programmed centre (partial arc)" : "least-squares centre per revolution"},
      {"radius_mean_deviation_um", number_or_null(c.radius_mean_deviation_um)},
      {"circular_deviation_G_um", number_or_null(c.circular_deviation_G_um)},
      {"circular_hysteresis_H_um",
       c.circular_hysteresis_H_um ? nlohmann::json(*c.circular_hysteresis_H_um) : nlohmann::json(nullptr)},
      {"radial_deviation_F_max_um", number_or_null(c.radial_deviation_F_max_um)},
      {"radial_deviation_F_min_um", number_or_null(c.radial_deviation_F_min_um)}};
  nlohmann::json centers = nlohmann::json::array();
  for (const auto& ctr : c.centers_mm) centers.push_back({ctr.x(), ctr.y()});
  j["revolution_centers_mm"] = centers;
  j["revolution_radii_mm"] = c.radii_mm;
  if (c.direction == "both") {
    j["circular_deviation_G_ccw_um"] = number_or_null(dsp::direction_G_um(c, "ccw"));
    j["circular_deviation_G_cw_um"] = number_or_null(dsp::direction_G_um(c, "cw"));
  }
  // G of the averaged revolution per direction (beside ISO 230-4's G over all revolutions).
  if (std::isfinite(c.direction_averaged_G_um[0])) j["averaged_revolution_G_ccw_um"] = c.direction_averaged_G_um[0];
  if (std::isfinite(c.direction_averaged_G_um[1])) j["averaged_revolution_G_cw_um"] = c.direction_averaged_G_um[1];
  // The trace thinned to at most ~3600 points per revolution set: the plots need no more.
  // (A trace already thinned as it streamed keeps exactly these points: all of them go.)
  const std::size_t n = c.trace.angle_deg.size();
  const std::size_t step = c.trace.stride > 1 ? 1 : std::max<std::size_t>(1, n / 3600);
  nlohmann::json ang = nlohmann::json::array(), dev = nlohmann::json::array(), dir = nlohmann::json::array();
  for (std::size_t i = 0; i < n; i += step) {
    ang.push_back(std::round(c.trace.angle_deg[i] * 1000.0) / 1000.0);
    dev.push_back(std::round(c.trace.radius_deviation_um[i] * 1000.0) / 1000.0);
    dir.push_back(c.trace.direction[i]);
  }
  j["trace"] = {{"angle_deg", ang}, {"radius_deviation_um", dev}, {"direction", dir}};
  if (c.arc_deg < 360.0)
    j["arc_start_deg"] =
        program.arc_start_deg ? nlohmann::json(*program.arc_start_deg) : nlohmann::json(90.0 - c.arc_deg / 2.0);
  return j;
}

namespace {

// The spec's keys of each object, for the objects of a program whose evaluation failed:
// every key is present and null (results.md), the reason is already in quality.flags.
nlohmann::json all_null(std::initializer_list<const char*> keys) {
  nlohmann::json j = nlohmann::json::object();
  for (const char* k : keys) j[k] = nullptr;
  return j;
}

// `path` (a key's parts) nulled below `node`; through an array (the rectangle's sides),
// in each element. Whether anything was.
bool null_path(nlohmann::json& node, const std::vector<std::string>& path, std::size_t at) {
  if (node.is_array()) {
    bool any = false;
    for (auto& element : node) any = null_path(element, path, at) || any;
    return any;
  }
  if (at >= path.size() || !node.is_object() || !node.contains(path[at])) return false;
  if (at + 1 == path.size()) {
    node[path[at]] = nullptr;
    return true;
  }
  return null_path(node[path[at]], path, at + 1);
}

// A figure the analysis did not evaluate (Analysis::not_evaluated) is null, with its reason.
void null_not_evaluated(const dsp::Analysis& a, nlohmann::json& doc, std::vector<dsp::Flag>& flags) {
  for (const auto& [key, reason] : a.not_evaluated) {
    std::vector<std::string> path;
    for (std::size_t b = 0, e; b <= key.size(); b = e + 1) {
      e = std::min(key.find('.', b), key.size());
      path.push_back(key.substr(b, e - b));
    }
    if (null_path(doc, path, 0)) flags.push_back({dsp::FlagCode::figure_null, key, "not evaluated: " + reason});
  }
}

// A flag that says why `key` of program object `obj` is null: one on the figure itself, or
// one that left the whole object null.
bool explains(const dsp::Flag& f, const std::string& obj, const std::string& key) {
  if (f.figure == key) return true;
  return f.figure == obj && (f.code == dsp::FlagCode::figure_null || f.code == dsp::FlagCode::evaluation_failed);
}

// Every null figure of a program object must have a reason in quality.flags; a null the
// evaluation did not explain gets a generic one naming it (never silently null).
void explain_nulls(const nlohmann::json& doc, std::vector<dsp::Flag>& flags) {
  for (const char* obj : {"circle", "diagnostics", "positioning", "step", "rectangle", "freeform"}) {
    if (!doc.contains(obj) || !doc[obj].is_object()) continue;
    for (const auto& [key, value] : doc[obj].items()) {
      if (!value.is_null()) continue;
      const std::string name = std::string(obj) + "." + key;
      if (std::none_of(flags.begin(), flags.end(), [&](const dsp::Flag& f) { return explains(f, obj, name); }))
        flags.push_back({dsp::FlagCode::figure_null, name, {}});
    }
  }
}

constexpr const char* kAxisNames[3] = {"x", "y", "z"};

// The verdict, its reasons, the flags with each flag's code and severity.
nlohmann::json quality_json(const dsp::Analysis& a, const std::vector<dsp::Flag>& flags) {
  nlohmann::json q = {{"degraded", a.degraded},
                      {"verdict", dsp::verdict_name(a.verdict)},
                      {"verdict_reasons", a.verdict_reasons},
                      {"flags", dsp::flag_texts(flags)}};
  nlohmann::json codes = nlohmann::json::array(), figures = nlohmann::json::array(), severity = nlohmann::json::array();
  for (const dsp::Flag& f : flags) {
    codes.push_back(dsp::code_name(f.code));
    figures.push_back(f.figure);
    severity.push_back(dsp::severity_name(dsp::severity(f)));
  }
  q["flag_codes"] = codes;
  q["flag_figures"] = figures;
  q["flag_severity"] = severity;
  if (a.conformance) {  // ISO 14253-1 against the tolerances the analysis was given
    nlohmann::json figs = nlohmann::json::array();
    for (const auto& f : a.conformance->figures)
      figs.push_back({{"name", f.name},
                      {"key", f.key},
                      {"magnitude", f.magnitude},
                      {"uncertainty_k2", std::isfinite(f.u_k2) ? nlohmann::json(f.u_k2) : nlohmann::json(nullptr)},
                      {"tolerance", f.tolerance},
                      {"decision", dsp::conformance_key(f.decision)}});
    q["conformance"] = {{"rule", "ISO 14253-1, U with k = 2"},
                        {"overall", dsp::conformance_key(a.conformance->overall)},
                        {"figures", figs}};
  }
  return q;
}

// Each program's section of the result: the evaluation's, or, when it failed, every key
// null (a reader finds the section of the run's program either way).
void circle_section(const dsp::Program& p, const dsp::Analysis& a, nlohmann::json& j) {
  if (a.circle) {
    j["circle"] = circle_json(p, *a.circle);
  } else {
    j["circle"] = all_null({"radius_mean_deviation_um", "circular_deviation_G_um", "circular_hysteresis_H_um",
                            "radial_deviation_F_max_um", "radial_deviation_F_min_um"});
    j["circle"]["plane"] = p.plane;
    j["circle"]["radius_nominal_mm"] = p.radius_mm;
    j["circle"]["feed_mm_min"] = p.feed_mm_min;
    j["circle"]["arc_deg"] = p.arc_deg;
    j["circle"]["trace"] = {{"angle_deg", nlohmann::json::array()},
                            {"radius_deviation_um", nlohmann::json::array()},
                            {"direction", nlohmann::json::array()}};
  }
  j["diagnostics"] = a.diagnostics
                         ? diagnostics_json(*a.diagnostics)
                         : all_null({"backlash_x_um", "backlash_y_um", "reversal_spike_x_um", "reversal_spike_y_um",
                                     "lateral_play_x_um", "lateral_play_y_um", "cyclic_error_x_um", "cyclic_error_y_um",
                                     "servo_mismatch_ms", "squareness_urad", "scale_mismatch_ppm", "straightness_x_um",
                                     "straightness_y_um", "stick_slip_um", "vibration_um"});
}

void step_section(const dsp::Program& p, const dsp::Analysis& a, nlohmann::json& j) {
  if (a.step) {
    j["step"] = step_json(a.step_axis, *a.step);
  } else {
    j["step"] = all_null({"end_position_error_um", "scatter_um", "overshoot_um", "settling_s"});
    j["step"]["axis"] = p.axis;
  }
}

void positioning_section(const dsp::Program& p, const dsp::Analysis& a, nlohmann::json& j) {
  if (a.positioning && a.positioning_input) {
    j["positioning"] = positioning_json(*a.positioning_input, *a.positioning, true);
  } else {
    j["positioning"] = all_null({"deviation_um"});
    for (const auto& f : dsp::eval::iso230_2_figures({})) j["positioning"][f.key] = nullptr;
    j["positioning"]["axis"] = p.axis;
    j["positioning"]["targets_mm"] = p.targets_mm;
    j["positioning"]["runs"] = p.runs;
  }
}

void rectangle_section(const dsp::Program&, const dsp::Analysis& a, nlohmann::json& j) {
  j["rectangle"] = a.rectangle ? rectangle_json(*a.rectangle) : all_null({"corners_mm", "corner_errors_um"});
  j["rectangle"]["path_deviation"] = a.path ? path_json(*a.path) : nlohmann::json(nullptr);
}

void freeform_section(const dsp::Program&, const dsp::Analysis& a, nlohmann::json& j) {
  j["freeform"] =
      a.path ? path_json(*a.path) : all_null({"contour_error_max_um", "contour_error_rms_um", "tangential_rms_um"});
}

// Per ProgramKind, in the enum's order (the identification has no section: `eical
// identify` writes the calibration).
using SectionWriter = void (*)(const dsp::Program&, const dsp::Analysis&, nlohmann::json&);
constexpr std::array<std::pair<dsp::ProgramKind, SectionWriter>, 6> kSections = {{
    {dsp::ProgramKind::step, step_section},
    {dsp::ProgramKind::positioning, positioning_section},
    {dsp::ProgramKind::rectangle, rectangle_section},
    {dsp::ProgramKind::circle, circle_section},
    {dsp::ProgramKind::freeform, freeform_section},
    {dsp::ProgramKind::identify, nullptr},
}};

void add_program_section(const dsp::Program& p, const dsp::Analysis& a, nlohmann::json& j) {
  for (const auto& [kind, write] : kSections)
    if (kind == p.kind && write) write(p, a, j);
}

// How the pipeline ran: its windows, the dynamic compensation, NBS, Coriolis.
nlohmann::json pipeline_json(const dsp::Analysis& a) {
  const auto& m = a.measurement;
  return {{"rest_window_samples", m.rest_window_samples},
          {"zupt_window_samples", m.zupt_window_samples},
          {"zupt_velocity_error_mm_s",
           {m.zupt_velocity_error_mm_s.x(), m.zupt_velocity_error_mm_s.y(), m.zupt_velocity_error_mm_s.z()}},
          {"dynamic_compensation",
           a.dynamic == dsp::DynamicComp::none
               ? std::string("none (PT2 and DAQ delay uncompensated)")
               : std::string(dsp::dynamic_comp_name(a.dynamic)) + ", DAQ delay removed by re-indexing"},
          {"nbs", a.nbs},
          {"coriolis", a.coriolis}};
}

// What the supports did: accepted and rejected updates per kind and axis, the
// standstills found, the strips' readings, and the measurement's own noise-limited σ.
nlohmann::json supports_json(const dsp::Measurement& m, double g_mps2) {
  nlohmann::json sup;
  for (int k = 0; k < dsp::fusion::kSupportKinds; ++k) {
    nlohmann::json kind_j;
    for (int ax = 0; ax < 3; ++ax) {
      const auto& t = m.supports.tally[ax][k];
      kind_j[kAxisNames[ax]] = {{"accepted", t.accepted}, {"rejected", t.rejected}};
    }
    sup[dsp::fusion::support_name(static_cast<dsp::fusion::Support>(k))] = kind_j;
  }
  sup["standstills"] = m.supports.rest_windows.size();
  sup["psd_readings"] = m.supports.psd_fixes;
  sup["psd_disagrees"] = m.supports.psd_disagrees;
  sup["psd_crossings_merged"] = m.supports.psd_crossings_merged;
  sup["resets"] = m.supports.resets;
  sup["smoothed"] = m.supports.smoothed;
  // The bias jump per move start the smoother assumed and where it came from, beside what
  // the standstills showed; µg with the site's g, as pipeline_config() turned the data
  // sheet's µg into the model's µm/s².
  const double um_s2_per_ug = g_mps2;
  const auto& bs = m.supports.bias_step;
  const auto or_null = [&](double um_s2) {
    return bs.measured ? nlohmann::json(um_s2 / um_s2_per_ug) : nlohmann::json();
  };
  sup["bias_step"] = {{"ug", m.supports.bias_step_um_s2 / um_s2_per_ug},
                      {"source", m.supports.bias_step_from_standstills ? "standstills" : "model"},
                      {"standstills_ug", or_null(bs.step_um_s2)},
                      {"standstill_pairs", bs.pairs},
                      {"noise_ug_per_rthz", or_null(bs.noise_um_s2_rthz)}};
  // The scale of each axis whose strips span a distance, as they showed it (a state of the
  // fusion there: fusion/error_model.hpp); absent where no axis has one, or the strips were
  // dropped (psd_disagrees: nothing showed it).
  nlohmann::json scale;
  for (int ax = 0; ax < 3; ++ax) {
    const auto i = static_cast<std::size_t>(ax);
    if (dsp::fusion::scale_is_a_state(m.supports.scale_state_ppm, ax) && !m.supports.psd_disagrees)
      scale[kAxisNames[ax]] = {{"ppm", m.supports.scale_ppm[i]},
                               {"sigma_ppm", m.supports.scale_sigma_ppm[i]},
                               {"prior_sigma_ppm", m.supports.scale_state_ppm[i]}};
  }
  if (!scale.is_null()) sup["scale"] = scale;
  // Likewise the timing of each axis a strip measures: the error of the sensor model's
  // damping term and the DAQ's delay, as the strips crossed at speed showed it.
  nlohmann::json timing;
  for (int ax = 0; ax < 3; ++ax) {
    const auto i = static_cast<std::size_t>(ax);
    if (m.supports.timing_state_us[i] > 0.0 && !m.supports.psd_disagrees)
      timing[kAxisNames[ax]] = {{"us", m.supports.timing_us[i]},
                                {"sigma_us", m.supports.timing_sigma_us[i]},
                                {"prior_sigma_us", m.supports.timing_state_us[i]}};
  }
  if (!timing.is_null()) sup["timing"] = timing;
  const Eigen::Vector3d& worst = m.sigma_max_um;  // over the whole trace
  sup["position_sigma_max_um"] = {worst.x(), worst.y(), worst.z()};
  return sup;
}

// Repeats of one segment (between M102 marks) averaged sample by sample (6-44).
nlohmann::json repeats_json(const dsp::Analysis& a) {
  nlohmann::json reps = nlohmann::json::array();
  for (const auto& g : a.repeats) {
    nlohmann::json moving = nlohmann::json::array();
    for (int ax = 0; ax < 3; ++ax)
      if (g.axis_moves[ax]) moving.push_back(kAxisNames[ax]);
    reps.push_back({{"repeats", g.repeats()},
                    {"samples", g.samples},
                    {"axes", moving},
                    {"mean_deviation_rms_um", g.mean_rms_um},
                    {"scatter_rms_um", g.scatter_rms_um}});
  }
  return reps;
}

}  // namespace

nlohmann::json result_json(const dsp::Run& run, const dsp::Analysis& analysis) {
  nlohmann::json j;
  j["format"] = "eical-result/1";
  j["run_id"] = run.meta.id;
  j["program"] = dsp::program_kind_name(run.meta.program.kind);
  j["software"] = software_version();
  j["uncertainty_k2"] = per_figure_json(analysis, analysis.uncertainty_k2);
  j["noise_bound_k2"] = per_figure_json(analysis, analysis.noise_bound_k2);
  if (!analysis.uncertainty_budget.empty()) {
    nlohmann::json budget = nlohmann::json::object();
    for (const auto& [source, by_key] : analysis.uncertainty_budget)
      budget[dsp::uncertainty::error_source_key(source)] = per_figure_json(analysis, by_key);
    j["uncertainty_budget_k2"] = budget;
  }
  j["uncertainty"] = {
      {"coverage_factor", 2},
      {"noise_bound",
       "noise_bound_k2: the same evaluation of the ideal path with only the white noise measured at rest, fused by "
       "the smoother optimal for it over this run's supports (95th percentile of the draws)"},
      {"sensor_model", analysis.uncertainty_source},
      {"method", analysis.uncertainty_note},
      {"resolved_rule", "a figure is resolved when |value| > U (k = 2); one that is not is never compensated"}};
  j["sensor_model"] = {{"identified", analysis.sensor_model != "datasheet"}, {"source", analysis.sensor_model}};
  add_program_section(run.meta.program, analysis, j);
  if (analysis.circle_accuracy_rms_um) {
    j["reference_comparison"] = {
        {"reference", run.meta.reference ? run.meta.reference->kind : "ref"},
        {"radius_deviation_error_rms_um", *analysis.circle_accuracy_rms_um},
        {"reference_circular_deviation_G_um", analysis.circle_reference->circular_deviation_G_um},
        {"reference_radius_mean_deviation_um", analysis.circle_reference->radius_mean_deviation_um}};
  }
  j["pipeline"] = pipeline_json(analysis);
  j["pipeline"]["supports"] = supports_json(analysis.measurement, run.meta.site.g_mps2);
  j["repeats"] = repeats_json(analysis);
  std::vector<dsp::Flag> flags = analysis.flags;
  null_not_evaluated(analysis, j, flags);
  explain_nulls(j, flags);
  j["quality"] = quality_json(analysis, flags);
  return j;
}

nlohmann::json path_json(const dsp::eval::PathDeviation& d) {
  // Thinned to at most ~5000 points: the plots need no more; the report's CSV has all.
  const std::size_t n = d.sample.size(), step = std::max<std::size_t>(1, n / 5000);
  nlohmann::json s = nlohmann::json::array(), nrm = nlohmann::json::array(), tan = nlohmann::json::array();
  for (std::size_t i = 0; i < n; i += step) {
    s.push_back(std::round(d.arc_length_mm[i] * 1e4) / 1e4);
    nrm.push_back(std::round(d.normal_um[i] * 1e3) / 1e3);
    tan.push_back(std::round(d.tangential_um[i] * 1e3) / 1e3);
  }
  return {{"contour_error_max_um", number_or_null(d.contour_error_max_um)},
          {"contour_error_rms_um", number_or_null(d.contour_error_rms_um)},
          {"tangential_rms_um", number_or_null(d.tangential_rms_um)},
          {"path_length_mm", n ? number_or_null(d.arc_length_mm.back()) : nlohmann::json(nullptr)},
          {"trace", {{"arc_length_mm", s}, {"normal_um", nrm}, {"tangential_um", tan}}}};
}

nlohmann::json positioning_json(const dsp::eval::PositioningInput& in, const dsp::eval::PositioningResult& r,
                                bool vdi3441) {
  nlohmann::json targets = nlohmann::json::array();
  for (const auto& t : r.targets)
    targets.push_back({{"target_mm", t.target_mm},
                       {"mean_up_um", t.mean_up_um},
                       {"mean_down_um", t.mean_down_um},
                       {"mean_um", t.mean_um},
                       {"s_up_um", t.s_up_um},
                       {"s_down_um", t.s_down_um},
                       {"band_up_um", {t.mean_up_um - 2 * t.s_up_um, t.mean_up_um + 2 * t.s_up_um}},
                       {"band_down_um", {t.mean_down_um - 2 * t.s_down_um, t.mean_down_um + 2 * t.s_down_um}},
                       {"B_um", t.B_um},
                       {"R_up_um", t.R_up_um},
                       {"R_down_um", t.R_down_um},
                       {"R_um", t.R_um}});
  nlohmann::json j = {{"axis", r.axis},
                      {"targets_mm", in.targets_mm},
                      {"runs", r.runs},
                      {"deviation_um", {{"up", in.up_um}, {"down", in.down_um}}},
                      {"per_target", targets},
                      {"standard", "ISO 230-2:2014"},
                      {"within_standard", r.runs >= dsp::eval::kRunsPerTargetIso230_2}};
  for (const auto& f : dsp::eval::iso230_2_figures(r)) j[f.key] = f.value;
  if (vdi3441)
    for (const auto& f : dsp::eval::vdi3441_figures(r.vdi)) j["vdi3441"][f.key] = f.value;
  return j;
}

nlohmann::json diagnostics_json(const dsp::eval::CircleDiagnostics& d) {
  nlohmann::json j = {
      {"backlash_x_um", number_or_null(d.backlash_x_um)},
      {"backlash_y_um", number_or_null(d.backlash_y_um)},
      {"reversal_spike_x_um", number_or_null(d.reversal_spike_x_um)},
      {"reversal_spike_y_um", number_or_null(d.reversal_spike_y_um)},
      {"lateral_play_x_um", number_or_null(d.lateral_play_x_um)},
      {"lateral_play_y_um", number_or_null(d.lateral_play_y_um)},
      {"cyclic_error_x_um", number_or_null(d.cyclic_error_x_um)},
      {"cyclic_error_y_um", number_or_null(d.cyclic_error_y_um)},
      {"cyclic_pitch_mm", number_or_null(d.cyclic_pitch_mm)},
      {"servo_mismatch_ms", d.servo_and_squareness_separated ? number_or_null(d.servo_mismatch_ms) : nullptr},
      {"squareness_urad", number_or_null(d.squareness_urad)},
      {"scale_mismatch_ppm", number_or_null(d.scale_mismatch_ppm)},
      {"straightness_x_um", number_or_null(d.straightness_x_um)},
      {"straightness_y_um", number_or_null(d.straightness_y_um)},
      {"stick_slip_um", number_or_null(d.stick_slip_um)},
      {"vibration_um", number_or_null(d.vibration_um)},
      {"servo_lag_x_ms", number_or_null(d.lag_x_ms)},
      {"servo_lag_y_ms", number_or_null(d.lag_y_ms)},
      {"model_residual_rms_um", number_or_null(d.residual_rms_um)},
      {"notes", d.notes},
  };
  return j;
}

nlohmann::json step_json(const std::string& axis, const dsp::eval::StepResult& r) {
  nlohmann::json moves = nlohmann::json::array();
  bool any_settled = false;
  std::map<std::pair<long long, int>, int> repeats;  // (target nm, direction) → moves: scatter needs a repeat
  double largest = 0.0;
  for (const auto& m : r.moves) {
    largest = std::max(largest, std::abs(m.step_measured_um));
    any_settled |= m.settled;
    ++repeats[{std::llround(m.to_mm * 1e6), m.to_mm > m.from_mm ? 1 : -1}];
    moves.push_back({{"from_mm", m.from_mm},
                     {"to_mm", m.to_mm},
                     {"step_measured_um", m.step_measured_um},
                     {"end_error_um", m.end_error_um},
                     {"overshoot_um", m.overshoot_um},
                     {"settling_s", m.settled ? nlohmann::json(m.settling_s) : nlohmann::json(nullptr)},
                     {"resolved", m.resolved}});
  }
  const bool has_repeat = std::any_of(repeats.begin(), repeats.end(), [](const auto& kv) { return kv.second > 1; });
  return {{"axis", axis},
          {"end_position_error_um", number_or_null(r.end_position_error_um)},
          {"scatter_um", has_repeat ? number_or_null(r.scatter_um) : nlohmann::json(nullptr)},
          {"overshoot_um", number_or_null(r.overshoot_um)},
          {"settling_s", any_settled ? number_or_null(r.settling_s) : nlohmann::json(nullptr)},
          {"noise_um", number_or_null(r.noise_um)},
          {"smallest_step_resolved_um",
           r.smallest_step_resolved_um > 0 ? number_or_null(r.smallest_step_resolved_um) : nlohmann::json(nullptr)},
          {"largest_step_measured_um", number_or_null(largest)},
          {"moves", moves}};
}

nlohmann::json rectangle_json(const dsp::eval::RectangleResult& r) {
  nlohmann::json corners = nlohmann::json::array(), errors = nlohmann::json::array(), sides = nlohmann::json::array();
  for (const auto& c : r.corners_mm) corners.push_back({c.x(), c.y()});
  double worst = 0.0;
  for (const auto& e : r.corner_errors_um) errors.push_back({e.x(), e.y()}), worst = std::max(worst, e.norm());
  for (const auto& s : r.sides)
    sides.push_back({{"from_mm", {s.from_mm.x(), s.from_mm.y()}},
                     {"to_mm", {s.to_mm.x(), s.to_mm.y()}},
                     {"straightness_um", s.straightness_um},
                     {"direction_error_urad", s.direction_error_urad}});
  return {{"corners_mm", corners},
          {"corner_errors_um", errors},
          {"corner_error_max_um", r.corner_errors_um.empty() ? nlohmann::json(nullptr) : nlohmann::json(worst)},
          {"sides", sides},
          {"corner_angle_error_urad", r.corner_angle_error_urad}};
}

}  // namespace eical::drivers
