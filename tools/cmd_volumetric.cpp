// eical volumetric: the 21-parameter model of a 3-axis machine (seed 004).
// * --model M.toml --points P.csv --out O.csv: deviation vectors at points (x,y,z,xp,yp,zp
//   in mm) → ex_um,ey_um,ez_um,status (ok | out_of_range:<axis>), and, for a fitted model
//   with uncertainties, Ux_um,Uy_um,Uz_um (k = 2, of e(x) − e(origin)).
// * --fit RUN... -o M.toml: the components eical's runs observe (dsp/comp/volumetric_fit),
//   written as eical-volumetric/1 with u_k2 per support point and, for every component it
//   cannot observe, observed = false and why.
#include "drivers/config/strict_toml.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/comp/volumetric_fit.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/io/csv_table.hpp"
#include "tools/run_files.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>

namespace eical::tools {
namespace {

using dsp::comp::kVolumetricComponents;

dsp::comp::VolumetricFit read_model(const std::string& file) {
  const toml::table root = drivers::StrictTable::parse_file(file);
  drivers::StrictTable t(root, file, "");
  const std::string format = t.string("format");
  if (format != "eical-volumetric/1") t.fail("format", "expected \"eical-volumetric/1\", got \"" + format + "\"");
  dsp::comp::VolumetricFit f;
  dsp::comp::VolumetricModel& m = f.model;
  auto axes = t.table("axes");
  const char* keys[3] = {"x_range_mm", "y_range_mm", "z_range_mm"};
  for (int a = 0; a < 3; ++a) {
    const auto r = axes.numbers(keys[a], 2);
    m.range_mm[a] = {r[0], r[1]};
  }
  axes.finish();
  auto sq = t.table("squareness");
  m.xwy_urad = sq.number("xwy");
  m.xwz_urad = sq.number("xwz");
  m.ywz_urad = sq.number("ywz");
  const char* sq_u[3] = {"xwy_u_k2", "ywz_u_k2", "xwz_u_k2"};  // a fitted model's uncertainties
  for (int s = 0; s < 3; ++s)
    if (sq.has(sq_u[s])) f.squareness[s].observed = true, f.squareness[s].u_k2_urad = sq.number(sq_u[s]);
  sq.finish();
  std::array<bool, 18> seen{};
  for (auto& c : t.tables("component")) {
    const std::string name = c.string("name");
    int k = -1;
    for (int i = 0; i < 18; ++i)
      if (name == kVolumetricComponents[i]) k = i;
    if (k < 0) c.fail("name", "'" + name + "' is not one of xtx, xty, ..., zrz");
    if (seen[k]) c.fail("name", "component '" + name + "' appears twice");
    seen[k] = true;
    m.component[k].pos_mm = c.numbers("positions_mm");
    m.component[k].values = c.numbers("values");
    auto& fit = f.component[k];
    if (c.has("u_k2")) {
      fit.u_k2 = c.numbers("u_k2", m.component[k].pos_mm.size());
      fit.observed = true;
    }
    if (!c.boolean("observed", true)) fit.observed = false, fit.u_k2.clear();
    fit.note = c.string("note", "");
    c.finish();
  }
  t.finish();
  dsp::comp::validate(m);  // missing components, order, coverage
  return f;
}

bool has_uncertainty(const dsp::comp::VolumetricFit& f) {
  for (const auto& c : f.component)
    if (!c.u_k2.empty()) return true;
  return false;
}

std::string numbers(const std::vector<double>& v, const char* fmt = "%.6g") {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    char b[32];
    std::snprintf(b, sizeof b, fmt, v[i]);
    s += (i ? ", " : "") + std::string(b);
  }
  return s + "]";
}

std::string toml_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\\\"") : c == '\\' ? std::string("\\\\") : std::string(1, c);
  return o + "\"";
}

std::string model_toml(const dsp::comp::VolumetricFit& f, const std::vector<std::string>& runs) {
  const auto& m = f.model;
  std::string t = "# eical-volumetric/1 fitted by eical volumetric --fit from:\n";
  for (const auto& r : runs) t += "#   " + r + "\n";
  t += "# Translations (t) in um, rotations (r) and squareness (w) in urad, positions in mm; u_k2 the expanded\n"
       "# uncertainty (k = 2) of each value. Values are relative to the machine at the origin of the measured range.\n"
       "format = \"eical-volumetric/1\"\n\n[axes]\n";
  const char* keys[3] = {"x_range_mm", "y_range_mm", "z_range_mm"};
  for (int a = 0; a < 3; ++a) t += std::string(keys[a]) + " = " + numbers({m.range_mm[a][0], m.range_mm[a][1]}) + "\n";
  t += "\n[squareness]\n";
  const char* names[3] = {"xwy", "ywz", "xwz"};
  const double values[3] = {m.xwy_urad, m.ywz_urad, m.xwz_urad};
  for (int s = 0; s < 3; ++s) {
    char b[160];
    std::snprintf(b, sizeof b, "%s = %.4g  # %s\n", names[s], values[s], f.squareness[s].note.c_str());
    t += b;
    if (f.squareness[s].observed) {
      std::snprintf(b, sizeof b, "%s_u_k2 = %.4g\n", names[s], f.squareness[s].u_k2_urad);
      t += b;
    }
  }
  for (int k = 0; k < 18; ++k) {
    const auto& c = f.component[k];
    t += "\n[[component]]\nname = \"" + std::string(kVolumetricComponents[k]) + "\"\n";
    t += "positions_mm = " + numbers(m.component[k].pos_mm) + "\nvalues = " + numbers(m.component[k].values, "%.4f") + "\n";
    if (c.observed) t += "u_k2 = " + numbers(c.u_k2, "%.4f") + "\n";
    else t += "observed = false\n";
    t += "note = " + toml_string(c.note) + "\n";
  }
  return t;
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
      used.push_back(path + ": positioning along " + run.meta.program.axis + " (translations of " + run.meta.program.axis + " in x, y, z)");
    } else if (kind == "circle" && a.diagnostics) {
      const auto [u, v] = dsp::plane_axes(run.meta.program.plane);
      const int pair = (u == 0 && v == 1) ? 0 : (u == 1 && v == 2) ? 1 : 2;
      const nlohmann::json j = drivers::result_json(run, a);
      std::optional<double> uk2;
      if (j.contains("uncertainty_k2") && j["uncertainty_k2"].contains("diagnostics.squareness_urad") &&
          j["uncertainty_k2"]["diagnostics.squareness_urad"].is_number())
        uk2 = j["uncertainty_k2"]["diagnostics.squareness_urad"].get<double>();
      circles.push_back({pair, a.diagnostics->squareness_urad, uk2, path});
      used.push_back(path + ": circle " + run.meta.program.plane + (uk2 ? " (squareness)" : " (squareness without uncertainty: not used)"));
    } else if (kind == "rectangle") {
      used.push_back(path + ": rectangle not used: NBS holds the standing axis of each side at zero, which takes the squareness out with "
                            "the drift; without NBS the drift over a side buries it");
    } else {
      used.push_back(path + ": " + kind + " not used");
    }
  }
  const dsp::comp::VolumetricFit f = dsp::comp::fit_volumetric(passes, circles);
  write_file_atomic(out, model_toml(f, used));
  std::printf("volumetric fit -> %s\n", out.c_str());
  for (const auto& u : used) std::printf("  %s\n", u.c_str());
  for (int k = 0; k < 18; ++k)
    std::printf("  %s: %s%s\n", kVolumetricComponents[k], f.component[k].observed ? "" : "NOT OBSERVED — ", f.component[k].note.c_str());
  const char* names[3] = {"xwy", "ywz", "xwz"};
  const double values[3] = {f.model.xwy_urad, f.model.ywz_urad, f.model.xwz_urad};
  for (int s = 0; s < 3; ++s)
    if (f.squareness[s].observed) std::printf("  %s = %.1f urad (U = %.1f, k = 2)\n", names[s], values[s], f.squareness[s].u_k2_urad);
    else std::printf("  %s: NOT OBSERVED — %s\n", names[s], f.squareness[s].note.c_str());
}

}  // namespace

void register_volumetric(CLI::App& app) {
  struct Opt {
    std::string model, points, out;
    std::vector<std::string> fit;
    bool force = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("volumetric", "21-parameter volumetric model: deviations at points, or --fit the model from runs");
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
    if (o->model.empty() || o->points.empty()) throw dsp::InputError("volumetric: give --model and --points, or --fit RUN...");
    const auto f = read_model(o->model);
    const bool with_u = has_uncertainty(f);
    const CsvTable p(o->points, {"x", "y", "z", "xp", "yp", "zp"});
    std::string text = with_u ? "ex_um,ey_um,ez_um,status,Ux_um,Uy_um,Uz_um\n" : "ex_um,ey_um,ez_um,status\n";
    int out_of_range = 0;
    for (std::size_t r = 0; r < p.rows(); ++r) {
      const Eigen::Vector3d x(p.number(r, "x"), p.number(r, "y"), p.number(r, "z"));
      const Eigen::Vector3d xp(p.number(r, "xp"), p.number(r, "yp"), p.number(r, "zp"));
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
    std::printf("%zu points, %d out of range; written %s\n", p.rows(), out_of_range, o->out.c_str());
  });
}

}  // namespace eical::tools
