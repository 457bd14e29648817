// eical lincomp: piecewise-linear axis compensation table from an error curve (seed 002),
// with the worst residual over grid shifts, and exports for the control.
#include "dsp/comp/axis_table.hpp"
#include "dsp/comp/lincomp.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/comp/linuxcnc_export.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/run_files.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <memory>

namespace eical::tools {
namespace {

struct Curves {
  dsp::comp::ErrorCurve mean, up, down;  // up/down only from a positioning result
};

Curves read_curve_csv(const std::string& file) {
  Curves c;
  c.mean = c.up = c.down = read_error_curve_csv(file);
  return c;
}

// The positioning object of an eical-result/1 document: mean deviation per target and
// direction over the runs (ISO 230-2 x̄i↑, x̄i↓) and their bidirectional mean.
Curves read_positioning_json(const std::string& file) {
  std::ifstream is(file);
  if (!is) throw dsp::InputError(file + ": cannot open");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(is);
  } catch (const nlohmann::json::exception& e) {
    throw dsp::InputError(file + ": not JSON: " + e.what());
  }
  if (!j.contains("positioning") || !j["positioning"].is_object())
    throw dsp::InputError(file + ": no 'positioning' object");
  const auto& p = j["positioning"];
  const auto targets = p.at("targets_mm").get<std::vector<double>>();
  Curves c;
  for (const char* dir : {"up", "down"}) {
    const auto runs = p.at("deviation_um").at(dir).get<std::vector<std::vector<double>>>();
    auto& curve = std::string(dir) == "up" ? c.up : c.down;
    for (std::size_t i = 0; i < targets.size(); ++i) {
      double sum = 0.0;
      for (const auto& run : runs) {
        if (run.size() != targets.size())
          throw dsp::InputError(file + ": positioning.deviation_um." + dir + ": a run has the wrong number of targets");
        sum += run[i];
      }
      if (runs.empty()) throw dsp::InputError(file + ": positioning.deviation_um." + dir + " is empty");
      curve.pos_mm.push_back(targets[i]);
      curve.error_um.push_back(sum / static_cast<double>(runs.size()));
    }
  }
  c.mean = c.up;
  for (std::size_t i = 0; i < c.mean.error_um.size(); ++i)
    c.mean.error_um[i] = 0.5 * (c.up.error_um[i] + c.down.error_um[i]);
  return c;
}

// What `eical lincomp` is told.
struct LincompOptions {
  std::string curve, positioning, linuxcnc, csv;
  double spacing = 50.0, shift_step = 1.0, u = 0.0;
  std::vector<double> travel;
  bool json = false, force = false;
};

void add_lincomp_options(CLI::App& cmd, LincompOptions& o) {
  auto* in_curve = cmd.add_option("--curve", o.curve, "error curve CSV: pos_mm,error_um (error = actual - nominal)");
  auto* in_pos =
      cmd.add_option("--positioning", o.positioning,
                     "eical-result/1 JSON with a 'positioning' object: mean deviation per target is the curve");
  in_curve->excludes(in_pos);
  cmd.add_option("--spacing-mm", o.spacing, "correction point spacing A")->required()->check(CLI::PositiveNumber);
  cmd.add_option("--shift-step-mm", o.shift_step, "grid shift step")->default_val(1.0)->check(CLI::PositiveNumber);
  cmd.add_option("--period-error-um", o.u, "position error within one signal period u (magnitude)")
      ->default_val(0.0)
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--linuxcnc", o.linuxcnc, "write a LinuxCNC compensation file (COMP_FILE_TYPE = 0)");
  cmd.add_option("--csv", o.csv,
                 "write the table as CSV (pos_mm, deviation_um, correction_um = -deviation, per direction)");
  cmd.add_option("--travel-mm", o.travel, "MIN,MAX the table must cover (mm); refused when the curve does not")
      ->expected(2)
      ->delimiter(',');
  cmd.add_flag("--json", o.json, "print the result as JSON");
  cmd.add_flag("--force", o.force, "overwrite existing output files");
}

// The tables of both directions on the compensation grid.
struct DirectionTables {
  dsp::comp::CorrectionTable up, down;
};

std::string table_csv(const dsp::comp::LinCompResult& r, const DirectionTables& d) {
  std::string text = "pos_mm,deviation_um,correction_um,correction_up_um,correction_down_um\n";
  for (std::size_t i = 0; i < r.table.pos_mm.size(); ++i) {
    char line[200];
    std::snprintf(line, sizeof line, "%.4f,%.4f,%.4f,%.4f,%.4f\n", r.table.pos_mm[i], r.table.deviation_um[i],
                  dsp::comp::correction_from_deviation_um(r.table.deviation_um[i]),
                  dsp::comp::correction_from_deviation_um(d.up.deviation_um[i]),
                  dsp::comp::correction_from_deviation_um(d.down.deviation_um[i]));
    text += line;
  }
  return text;
}

// After every check: a bad input writes nothing, and nothing replaces a table a control
// may already load unless told (as eical comp).
void write_files(const std::vector<std::pair<std::string, std::string>>& files, bool force) {
  std::string existing;
  for (const auto& f : files)
    if (std::filesystem::exists(f.first)) existing += "\n  " + f.first;
  if (!existing.empty() && !force)
    throw dsp::InputError("lincomp: would overwrite existing file(s), nothing written (--force to replace them):" +
                          existing);
  for (const auto& [file, text] : files) write_file_atomic(file, text);
}

void print_result(const dsp::comp::LinCompResult& r, const LincompOptions& o) {
  if (o.json) {
    nlohmann::json points = nlohmann::json::array();
    for (std::size_t i = 0; i < r.table.pos_mm.size(); ++i)
      points.push_back({{"pos_mm", r.table.pos_mm[i]},
                        {"deviation_um", r.table.deviation_um[i]},
                        {"correction_um", dsp::comp::correction_from_deviation_um(r.table.deviation_um[i])}});
    const nlohmann::json j = {{"spacing_mm", r.spacing_mm},
                              {"max_residual_um", r.max_residual_um},
                              {"worst_shift_mm", r.worst_shift_mm},
                              {"total_um", r.total_um},
                              {"period_error_um", o.u},
                              {"residual_unshifted_um", r.residual_unshifted_um},
                              {"shift_step_mm", o.shift_step},
                              {"table", points}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf(
        "spacing %.3f mm: F_rest %.3f um (worst grid shift %.1f mm), F_total = F_rest + u = %.3f um, %zu correction "
        "points\n",
        r.spacing_mm, r.max_residual_um, r.worst_shift_mm, r.total_um, r.table.pos_mm.size());
  }
}

void run_lincomp(const LincompOptions& o) {
  if (o.curve.empty() && o.positioning.empty()) throw dsp::InputError("lincomp: give --curve or --positioning");
  const Curves c = o.curve.empty() ? read_positioning_json(o.positioning) : read_curve_csv(o.curve);
  const dsp::comp::LinCompOptions opt{o.spacing, o.shift_step, o.u};
  const auto r = dsp::comp::piecewise_linear(c.mean, opt);  // validates before anything is written
  const DirectionTables d{dsp::comp::correction_table(c.up, c.up.pos_mm.front(), o.spacing),
                          dsp::comp::correction_table(c.down, c.down.pos_mm.front(), o.spacing)};
  // One sign convention (dsp/comp/axis_table.hpp): deviation = actual − nominal,
  // correction = −deviation, in every export.
  dsp::comp::AxisTable table;
  table.axis = 0;
  table.pos_mm = d.up.pos_mm;
  table.forward_um = d.up.deviation_um;
  table.reverse_um = d.down.deviation_um;
  if (o.travel.size() == 2) dsp::comp::require_coverage(table, o.travel[0], o.travel[1], "--travel-mm asks for");
  std::vector<std::pair<std::string, std::string>> files;
  if (!o.linuxcnc.empty())
    files.emplace_back(o.linuxcnc,
                       comp::linuxcnc_comp_file(table, "eical lincomp: spacing " + std::to_string(o.spacing) + " mm"));
  if (!o.csv.empty()) files.emplace_back(o.csv, table_csv(r, d));
  write_files(files, o.force);
  print_result(r, o);
}

}  // namespace

void register_lincomp(CLI::App& app) {
  auto o = std::make_shared<LincompOptions>();
  auto* cmd = app.add_subcommand("lincomp",
                                 "Piecewise-linear axis compensation table with its worst residual over grid shifts");
  add_lincomp_options(*cmd, *o);
  cmd->callback([o] { run_lincomp(*o); });
}

}  // namespace eical::tools
