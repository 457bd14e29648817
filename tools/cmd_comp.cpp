// eical comp INPUT...: compensation proposals for the control from measured results —
// positioning runs give each axis its deviation table (the reversal folded in), circles
// the backlash of axes without one — written for LinuxCNC (INI sections, COMP_FILEs, or
// merged into the machine's INI), SINUMERIK, FANUC and HEIDENHAIN, with comp.json saying
// which figure each term comes from. Never from a figure that is not resolved (unless
// told), never over an existing file (unless --force); on any error nothing is written.
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/comp/comp_plan.hpp"
#include "tools/comp/fanuc_export.hpp"
#include "tools/comp/heidenhain_export.hpp"
#include "tools/comp/linuxcnc_export.hpp"
#include "tools/comp/sinumerik_export.hpp"
#include "tools/io/psd_option.hpp"
#include "tools/run_files.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>

namespace eical::tools {
namespace {

namespace fs = std::filesystem;
using comp::AxisProposal;
using comp::OutputFile;

// What `eical comp` is told.
struct CompOptions {
  std::vector<std::string> inputs, controls = {"linuxcnc"}, travel, sinumerik_axes = {"X1", "Y1", "Z1"};
  std::string out = "comp", merge_ini;
  double spacing_mm = 0.0, fanuc_unit_um = 1.0, fanuc_reference_mm = 0.0;
  bool force = false, allow_unresolved = false, skip_unresolved = false, refuse_unresolved = false;
};

comp::TravelRange travel_range(const std::string& s) {
  const TravelOption t = parse_travel(s);
  comp::TravelRange r;  // member by member: GCC 12 misreads the aggregate's string (-Warray-bounds)
  r.axis = t.axis, r.from_mm = t.lo_mm, r.to_mm = t.hi_mm;
  r.who = "--travel asks for";
  return r;
}

std::string slurp(const std::string& file) {
  std::ifstream is(file, std::ios::binary);
  if (!is) throw dsp::InputError(file + ": cannot open");
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

std::vector<OutputFile> linuxcnc_outputs(const std::vector<AxisProposal>& axes, const CompOptions& o,
                                         nlohmann::json& axes_json) {
  std::map<char, int> joints = {{'x', 0}, {'y', 1}, {'z', 2}};
  std::string ini_text;
  if (!o.merge_ini.empty()) ini_text = slurp(o.merge_ini), joints = comp::joint_map(ini_text, o.merge_ini);
  std::vector<comp::JointSettings> settings;
  std::vector<OutputFile> out;
  for (const auto& p : axes) {
    const char a = dsp::comp::axis_letter(p.axis);
    if (!joints.count(a)) throw dsp::InputError(o.merge_ini + ": no joint moves axis " + std::string(1, a));
    comp::JointSettings j;
    j.joint = joints[a];
    j.axis = a;
    j.comments.push_back("axis " + std::string(1, a) + ": " + p.source);
    if (p.table) {
      const std::string name = "eical_joint" + std::to_string(j.joint) + ".comp";
      j.comp_file = name;
      j.comments.push_back(
          "the reversal is folded into the table's forward/reverse columns (LinuxCNC does not use BACKLASH with a "
          "COMP_FILE)");
      out.push_back(
          {"linuxcnc/" + name, comp::linuxcnc_comp_file(*p.table, "eical comp, joint " + std::to_string(j.joint) +
                                                                      " (" + std::string(1, a) + "): " + p.source)});
    } else {
      j.backlash_mm = *p.lost_motion_um * 1e-3;
    }
    axes_json[std::string(1, a)]["linuxcnc_joint"] = j.joint;
    settings.push_back(j);
  }
  out.push_back({"linuxcnc/eical-comp.ini",
                 comp::linuxcnc_ini_snippet(
                     settings,
                     "# eical comp: proposed LinuxCNC settings, one section per joint; merge into the machine's INI\n"
                     "# (or run eical comp with --merge-ini) and copy the .comp files next to it.\n")});
  if (!o.merge_ini.empty())
    out.push_back({"linuxcnc/" + fs::path(o.merge_ini).filename().string(),
                   comp::merge_linuxcnc_ini(ini_text, o.merge_ini, settings)});
  return out;
}

nlohmann::json axis_json(const AxisProposal& p) {
  nlohmann::json j = {{"source", p.source}};
  if (p.table) {
    nlohmann::json pts = nlohmann::json::array();
    const auto& t = *p.table;
    for (std::size_t i = 0; i < t.pos_mm.size(); ++i)
      pts.push_back({{"pos_mm", t.pos_mm[i]},
                     {"forward_deviation_um", t.forward_um[i]},
                     {"reverse_deviation_um", t.reverse_um[i]},
                     {"forward_correction_um", dsp::comp::correction_from_deviation_um(t.forward_um[i])},
                     {"reverse_correction_um", dsp::comp::correction_from_deviation_um(t.reverse_um[i])}});
    j["table"] = pts;
    j["lost_motion_in_table_um"] = t.mean_lost_motion_um();
  }
  if (p.lost_motion_um) j["lost_motion_um"] = *p.lost_motion_um;
  return j;
}

void add_comp_options(CLI::App& cmd, CompOptions& o) {
  cmd.add_option("inputs", o.inputs,
                 "eical-result/1 files (eical analyze --json) or run directories: positioning and circle runs")
      ->required();
  cmd.add_option("-o,--out", o.out, "output folder")->default_val("comp");
  cmd.add_option("--control", o.controls, "linuxcnc, sinumerik, fanuc, heidenhain or all (comma separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"linuxcnc", "sinumerik", "fanuc", "heidenhain", "all"}))
      ->default_str("linuxcnc");
  cmd.add_option("--merge-ini", o.merge_ini,
                 "LinuxCNC machine INI: also write it with the [JOINT_n] keys merged (trivkins)")
      ->check(CLI::ExistingFile);
  cmd.add_option("--spacing-mm", o.spacing_mm,
                 "interval of the equidistant SINUMERIK/FANUC/HEIDENHAIN tables (default: mean target spacing)")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--travel", o.travel,
                 "AXIS:MIN,MAX the table must cover (mm), besides what the inputs measured (repeatable)");
  cmd.add_option("--sinumerik-axes", o.sinumerik_axes, "SINUMERIK machine axis names of x, y, z")
      ->delimiter(',')
      ->expected(3);
  cmd.add_option("--fanuc-detection-unit-um", o.fanuc_unit_um, "FANUC detection unit")
      ->default_val(1.0)
      ->check(CLI::PositiveNumber);
  cmd.add_option("--fanuc-reference-mm", o.fanuc_reference_mm,
                 "FANUC reference position (machine coordinate) of No. 3620")
      ->default_val(0.0);
  cmd.add_flag("--force", o.force, "overwrite existing output files");
  auto* allow = cmd.add_flag(
      "--allow-unresolved", o.allow_unresolved,
      "propose terms from figures not larger than their uncertainty (or without one), marked in comp.json");
  auto* skip = cmd.add_flag("--skip-unresolved", o.skip_unresolved,
                            "leave out the terms whose figure is not resolved, and list them (the default)");
  auto* refuse =
      cmd.add_flag("--refuse-unresolved", o.refuse_unresolved, "write nothing when any term's figure is not resolved");
  allow->excludes(skip);
  allow->excludes(refuse);
  skip->excludes(refuse);
}

// The inputs' proposal per axis; refuses to go on when no term is left.
comp::Plan comp_plan(const std::vector<comp::CompInput>& inputs, const CompOptions& o) {
  comp::PlanOptions po;
  // Left out by default: a machine whose one axis has no backlash is the normal case, and
  // what is resolved is still worth compensating (issue 33).
  po.unresolved = o.allow_unresolved    ? comp::Unresolved::allow
                  : o.refuse_unresolved ? comp::Unresolved::refuse
                                        : comp::Unresolved::skip;
  for (const auto& t : o.travel) po.travel.push_back(travel_range(t));
  comp::Plan plan = comp::build_plan(inputs, po);
  if (plan.axes.empty()) {
    std::string msg = "comp: no term is resolved (|value| must exceed U, k = 2); nothing written";
    for (const auto& u : plan.unresolved_skipped) msg += "\n  not resolved: " + u;
    if (!plan.unresolved_skipped.empty())
      msg += "\n  measure again (more runs or revolutions), or --allow-unresolved to propose them anyway";
    throw dsp::InputError(msg);
  }
  return plan;
}

// The files of every control asked for; the LinuxCNC joints go into `axes`.
std::vector<OutputFile> control_files(const comp::Plan& plan, const CompOptions& o, nlohmann::json& axes) {
  std::set<std::string> controls(o.controls.begin(), o.controls.end());
  if (controls.count("all")) controls = {"linuxcnc", "sinumerik", "fanuc", "heidenhain"};
  std::vector<OutputFile> files;
  const comp::GridOptions grid{o.spacing_mm};
  if (controls.count("linuxcnc"))
    for (auto& f : linuxcnc_outputs(plan.axes, o, axes)) files.push_back(std::move(f));
  if (controls.count("sinumerik"))
    for (auto& f : comp::sinumerik_outputs(plan.axes, {grid, o.sinumerik_axes})) files.push_back(std::move(f));
  if (controls.count("fanuc"))
    for (auto& f : comp::fanuc_outputs(plan.axes, {grid, o.fanuc_unit_um, o.fanuc_reference_mm, 0}))
      files.push_back(std::move(f));
  if (controls.count("heidenhain"))
    for (auto& f : comp::heidenhain_outputs(plan.axes, {grid})) files.push_back(std::move(f));
  return files;
}

// comp.json: which figure each term comes from, the inputs, the files written.
nlohmann::json comp_json(const comp::Plan& plan, const nlohmann::json& axes, const std::vector<comp::CompInput>& inputs,
                         const std::vector<OutputFile>& files) {
  nlohmann::json j = {{"format", "eical-comp/1"},
                      {"sign_convention",
                       "deviation = actual - nominal; correction = -deviation, what the control adds to the command"},
                      {"axes", axes},
                      {"figures", plan.figures},
                      {"not_compensated", plan.not_compensated},
                      {"skipped", plan.skipped}};
  nlohmann::json ins = nlohmann::json::array();
  for (const auto& in : inputs)
    ins.push_back({{"input", in.name}, {"run_id", in.run_id}, {"program", in.result.value("program", std::string())}});
  j["inputs"] = ins;
  if (!plan.unresolved_used.empty()) j["proposed_from_unresolved_figures"] = plan.unresolved_used;
  if (!plan.unresolved_skipped.empty()) j["left_out_unresolved_figures"] = plan.unresolved_skipped;
  nlohmann::json names = nlohmann::json::array();
  for (const auto& f : files) names.push_back(f.path);
  j["files"] = names;
  return j;
}

// Nothing is written unless everything can be: existing files first.
void write_all_or_nothing(const std::vector<OutputFile>& files, const CompOptions& o) {
  std::vector<std::string> existing;
  for (const auto& f : files)
    if (fs::exists(fs::path(o.out) / f.path)) existing.push_back((fs::path(o.out) / f.path).string());
  if (!existing.empty() && !o.force) {
    std::string msg = "comp: would overwrite " + std::to_string(existing.size()) +
                      " existing file(s), nothing written (--force to replace them):";
    for (const auto& e : existing) msg += "\n  " + e;
    throw dsp::InputError(msg);
  }
  for (const auto& f : files) {
    const fs::path p = fs::path(o.out) / f.path;
    fs::create_directories(p.parent_path());
    write_file_atomic(p, f.text);
  }
}

void print_proposal(const comp::Plan& plan, std::size_t n_files, const CompOptions& o) {
  for (const auto& p : plan.axes) {
    const char a = dsp::comp::axis_letter(p.axis);
    if (p.table)
      std::printf("comp: %c table, %zu points %.3f .. %.3f mm, lost motion in it %.2f um (%s)\n", a,
                  p.table->pos_mm.size(), p.table->first_mm(), p.table->last_mm(), p.table->mean_lost_motion_um(),
                  p.source.c_str());
    else
      std::printf("comp: %c backlash %.2f um (%s)\n", a, *p.lost_motion_um, p.source.c_str());
  }
  for (const auto& u : plan.unresolved_used)
    std::printf("comp: WARNING proposed from an unresolved figure (--allow-unresolved): %s\n", u.c_str());
  for (const auto& u : plan.unresolved_skipped) std::printf("comp: left out, not resolved: %s\n", u.c_str());
  std::printf("comp: %zu files -> %s\n", n_files, o.out.c_str());
}

void run_comp(const CompOptions& o) {
  std::vector<comp::CompInput> inputs;
  for (const auto& p : o.inputs) inputs.push_back(comp::load_comp_input(p));
  const comp::Plan plan = comp_plan(inputs, o);
  nlohmann::json axes = nlohmann::json::object();
  for (const auto& p : plan.axes) axes[std::string(1, dsp::comp::axis_letter(p.axis))] = axis_json(p);
  std::vector<OutputFile> files = control_files(plan, o, axes);
  files.push_back({"comp.json", comp_json(plan, axes, inputs, files).dump(2) + "\n"});
  write_all_or_nothing(files, o);
  print_proposal(plan, files.size(), o);
}

}  // namespace

void register_comp(CLI::App& app) {
  auto o = std::make_shared<CompOptions>();
  auto* cmd = app.add_subcommand(
      "comp",
      "Propose axis compensation (tables with the reversal folded in, backlash) for the control from measured results");
  add_comp_options(*cmd, *o);
  cmd->callback([o] { run_comp(*o); });
}

}  // namespace eical::tools
