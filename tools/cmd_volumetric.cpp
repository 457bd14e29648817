// eical volumetric: the 21-parameter model of a 3-axis machine (seed 004).
// * --model M.toml --points P.csv --out O.csv: deviation vectors at points (x,y,z,xp,yp,zp
//   in mm) → ex_um,ey_um,ez_um,status (ok | out_of_range:<axis>), and, for a fitted model
//   with uncertainties, Ux_um,Uy_um,Uz_um (k = 2, of e(x) − e(origin)).
// * --fit RUN... -o M.toml: the components eical's runs observe (dsp/comp/volumetric_fit),
//   written as eical-volumetric/1 with u_k2 per support point and, for every component it
//   cannot observe, observed = false and why.
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/comp/volumetric_fit.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/io/volumetric_model_file.hpp"
#include "tools/run_files.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>

namespace eical::tools {
namespace {

using dsp::comp::kVolumetricComponents;

bool has_uncertainty(const dsp::comp::VolumetricFit& f) {
  for (const auto& c : f.component)
    if (!c.u_k2.empty()) return true;
  return false;
}

// Positioning runs give their standstills; circles their squareness (used with an
// uncertainty only); the others are named as not used.
void fit_from_runs(const std::vector<std::string>& runs, const std::string& out, bool force) {
  namespace fs = std::filesystem;
  if (fs::exists(out) && !force) throw dsp::InputError("volumetric: " + out + " exists (--force to replace it)");
  std::vector<dsp::comp::AxisPass> passes;
  std::vector<dsp::comp::SquarenessFigure> circles;
  std::vector<std::string> used;
  for (const auto& path : runs) {
    const dsp::Run run = drivers::read_run(path);
    const dsp::Analysis a = dsp::analyze_run(run);
    const auto& kind = run.meta.program.kind;
    if (kind == "positioning") {
      const int axis = dsp::axis_index(run.meta.program.axis);
      passes.push_back({axis, path, dsp::comp::standstills(a.measurement)});
      used.push_back(path + ": positioning along " + run.meta.program.axis + " (translations of " +
                     run.meta.program.axis + " in x, y, z)");
    } else if (kind == "circle" && a.diagnostics) {
      const auto [u, v] = dsp::plane_axes(run.meta.program.plane);
      const int pair = (u == 0 && v == 1) ? 0 : (u == 1 && v == 2) ? 1 : 2;
      const nlohmann::json j = drivers::result_json(run, a);
      std::optional<double> uk2;
      if (j.contains("uncertainty_k2") && j["uncertainty_k2"].contains("diagnostics.squareness_urad") &&
          j["uncertainty_k2"]["diagnostics.squareness_urad"].is_number())
        uk2 = j["uncertainty_k2"]["diagnostics.squareness_urad"].get<double>();
      circles.push_back({pair, a.diagnostics->squareness_urad, uk2, path});
      used.push_back(path + ": circle " + run.meta.program.plane +
                     (uk2 ? " (squareness)" : " (squareness without uncertainty: not used)"));
    } else if (kind == "rectangle") {
      used.push_back(
          path +
          ": rectangle not used: NBS holds the standing axis of each side at zero, which takes the squareness out with "
          "the drift; without NBS the drift over a side buries it");
    } else {
      used.push_back(path + ": " + kind + " not used");
    }
  }
  const dsp::comp::VolumetricFit f = dsp::comp::fit_volumetric(passes, circles);
  write_file_atomic(out, volumetric_model_toml(f, used));
  std::printf("volumetric fit -> %s\n", out.c_str());
  for (const auto& u : used) std::printf("  %s\n", u.c_str());
  for (int k = 0; k < 18; ++k)
    std::printf("  %s: %s%s\n", kVolumetricComponents[k], f.component[k].observed ? "" : "NOT OBSERVED — ",
                f.component[k].note.c_str());
  const char* names[3] = {"xwy", "ywz", "xwz"};
  const double values[3] = {f.model.xwy_urad, f.model.ywz_urad, f.model.xwz_urad};
  for (int s = 0; s < 3; ++s)
    if (f.squareness[s].observed)
      std::printf("  %s = %.1f urad (U = %.1f, k = 2)\n", names[s], values[s], f.squareness[s].u_k2_urad);
    else
      std::printf("  %s: NOT OBSERVED — %s\n", names[s], f.squareness[s].note.c_str());
}

}  // namespace

void register_volumetric(CLI::App& app) {
  struct Opt {
    std::string model, points, out;
    std::vector<std::string> fit;
    bool force = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("volumetric",
                                 "21-parameter volumetric model: deviations at points, or --fit the model from runs");
  auto* model = cmd->add_option("--model", o->model, "model file (eical-volumetric/1 TOML)");
  auto* points = cmd->add_option("--points", o->points, "CSV x,y,z,xp,yp,zp in mm (position and tool offset)");
  cmd->add_option("--out,-o", o->out, "output: CSV of deviations, or with --fit the model file")->required();
  auto* fit = cmd->add_option("--fit", o->fit, "positioning, circle (and other) run directories to fit the model from");
  cmd->add_flag("--force", o->force, "with --fit: replace an existing model file");
  fit->excludes(model)->excludes(points);
  cmd->callback([o] {
    if (!o->fit.empty()) {
      fit_from_runs(o->fit, o->out, o->force);
      return;
    }
    if (o->model.empty() || o->points.empty())
      throw dsp::InputError("volumetric: give --model and --points, or --fit RUN...");
    const auto f = read_volumetric_model(o->model);
    const bool with_u = has_uncertainty(f);
    const auto at = read_volumetric_points_csv(o->points);
    std::string text = with_u ? "ex_um,ey_um,ez_um,status,Ux_um,Uy_um,Uz_um\n" : "ex_um,ey_um,ez_um,status\n";
    int out_of_range = 0;
    for (const auto& [x, xp] : at) {
      const auto d = dsp::comp::volumetric_deviation(f.model, x, xp);
      char line[240];
      if (d.ok()) {
        std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,ok", d.e_um.x(), d.e_um.y(), d.e_um.z());
        text += line;
        if (with_u) {
          const Eigen::Vector3d u = dsp::comp::prediction_u_k2(f, x);
          std::snprintf(line, sizeof line, ",%.6f,%.6f,%.6f", u.x(), u.y(), u.z());
          text += line;
        }
        text += "\n";
      } else {
        std::snprintf(line, sizeof line, ",,,out_of_range:%c%s\n", "xyz"[d.out_of_range_axis], with_u ? ",,," : "");
        text += line, ++out_of_range;
      }
    }
    write_file_atomic(o->out, text);  // only after every row was computed: no partial file
    std::printf("%zu points, %d out of range; written %s\n", at.size(), out_of_range, o->out.c_str());
  });
}

}  // namespace eical::tools
