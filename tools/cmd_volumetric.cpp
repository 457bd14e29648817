// eical volumetric: the 21-parameter model of a 3-axis machine (seed 004).
// * --model M.toml --points P.csv --out O.csv: deviation vectors at points (x,y,z,xp,yp,zp
//   in mm) → ex_um,ey_um,ez_um,status (ok | out_of_range:<axis>), and, for a fitted model
//   with uncertainties, Ux_um,Uy_um,Uz_um (k = 2, of e(x) − e(origin)).
// * --fit RUN... -o M.toml [--calibration CAL]: the components eical's runs observe
//   (dsp/comp/volumetric_fit), written as eical-volumetric/1 with u_k2 per support point
//   (from each run's Monte Carlo draws) and, for every component it cannot observe,
//   observed = false and why. Runs with a critical flag are left out and listed with it.
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"
#include "dsp/analysis/verdict.hpp"
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
#include <optional>

namespace eical::tools {
namespace {

using dsp::comp::kVolumetricComponents;

bool has_uncertainty(const dsp::comp::VolumetricFit& f) {
  for (const auto& c : f.component)
    if (!c.u_k2.empty()) return true;
  return false;
}

std::string value_key(int c) { return std::string("volumetric.") + "xyz"[c] + "_um"; }
std::string slope_key(int c) { return std::string("volumetric.slope_") + "xyz"[c] + "_um_per_mm"; }

// A positioning run's share of the model as figures, for its uncertainty's draws to
// evaluate on every perturbed path (AnalysisOptions::more_figures). Empty when
// the run gives none: the full analysis says why (the same function throws there).
std::vector<dsp::FigureValue> run_figures(int axis, const dsp::Analysis& a) {
  dsp::comp::RunComponents r;
  try {
    r = dsp::comp::run_components(axis, dsp::comp::standstills(a.measurement));
  } catch (const dsp::InputError&) {
    return {};
  }
  std::vector<dsp::FigureValue> f;
  for (int c = 0; c < 3; ++c) {
    const auto& ch = r.channel[static_cast<std::size_t>(c)];
    f.push_back({value_key(c), ch.value_um, true, 1});
    if (c != axis) f.push_back({slope_key(c), {ch.slope_um_per_mm}, false, 1});
  }
  return f;
}

// The run's U (k = 2) of its components, from its draws; InputError when it has none.
dsp::comp::AxisPass pass_of(const std::string& path, int axis, const dsp::Analysis& a) {
  dsp::comp::AxisPass p;
  p.axis = axis, p.source = path;
  p.fit = dsp::comp::run_components(axis, dsp::comp::standstills(a.measurement));
  auto u_of = [&](const std::string& key, std::size_t n) {
    const auto it = a.uncertainty_k2.find(key);
    if (it == a.uncertainty_k2.end() || it->second.size() != n)
      throw dsp::InputError("no uncertainty of " + key + (a.uncertainty_note.empty() ? "" : ": " + a.uncertainty_note));
    return it->second;
  };
  for (int c = 0; c < 3; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    p.u_k2_um[ci] = u_of(value_key(c), p.fit.channel[ci].pos_mm.size());
    if (c != axis) p.slope_u_k2_um_per_mm[ci] = u_of(slope_key(c), 1)[0];
  }
  return p;
}

// The critical flags of a run (dsp/analysis/verdict: lost frames, saturation, strips that
// disagree with the integration, a failed evaluation, ...): its measurement is wrong or
// incomplete in a way its U does not hold, so it must not feed the model.
std::string critical_reason(const dsp::Analysis& a) {
  std::string r;
  for (const dsp::Flag& f : a.flags)
    if (dsp::severity(f) == dsp::FlagSeverity::critical)
      r += (r.empty() ? "critical flag: " : "; ") + dsp::flag_text(f);
  return r;
}

// The runs the fit reads, and why each of the others is not used.
struct FitInputs {
  std::vector<dsp::comp::AxisPass> passes;
  std::vector<dsp::comp::SquarenessFigure> circles;
  std::vector<std::string> used, left_out;
};

// One run: analysed with the calibration when one is given (as eical analyze --calibration),
// its positioning components or circle squareness taken, or left out with the reason.
void take_run(const std::string& path, const std::optional<std::string>& calibration, FitInputs& in) {
  dsp::Run run = drivers::read_run(path);
  dsp::AnalysisOptions opt;
  if (calibration) drivers::apply_calibration(drivers::read_sensor_calibration(*calibration, run.meta), run.meta, opt);
  const auto& kind = run.meta.program.kind;
  const int axis = kind == dsp::ProgramKind::positioning ? dsp::axis_index(run.meta.program.axis) : -1;
  if (axis >= 0) opt.more_figures = [axis](const dsp::Analysis& a) { return run_figures(axis, a); };
  const dsp::Analysis a = dsp::analyze_run(run, opt);
  if (const std::string why = critical_reason(a);
      !why.empty() && (kind == dsp::ProgramKind::positioning || kind == dsp::ProgramKind::circle)) {
    in.left_out.push_back(path + ": left out, " + why);
    return;
  }
  if (axis >= 0) {
    try {
      in.passes.push_back(pass_of(path, axis, a));
    } catch (const dsp::InputError& e) {
      in.left_out.push_back(path + ": left out, " + e.what());
      return;
    }
    in.used.push_back(path + ": positioning along " + run.meta.program.axis + " (translations of " +
                      run.meta.program.axis + " in x, y, z)");
  } else if (kind == dsp::ProgramKind::circle && a.diagnostics) {
    const auto [u, v] = dsp::plane_axes(run.meta.program.plane);
    const int pair = (u == 0 && v == 1) ? 0 : (u == 1 && v == 2) ? 1 : 2;
    const auto it = a.uncertainty_k2.find("diagnostics.squareness_urad");
    std::optional<double> uk2;
    if (it != a.uncertainty_k2.end() && it->second.size() == 1) uk2 = it->second[0];
    in.circles.push_back({pair, a.diagnostics->squareness_urad, uk2, path});
    in.used.push_back(path + ": circle " + run.meta.program.plane +
                      (uk2 ? " (squareness)" : " (squareness without uncertainty: not used)"));
  } else if (kind == dsp::ProgramKind::rectangle) {
    in.used.push_back(
        path +
        ": rectangle not used: NBS holds the standing axis of each side at zero, which takes the squareness out with "
        "the drift; without NBS the drift over a side buries it");
  } else {
    in.used.push_back(path + ": " + dsp::program_kind_name(kind) + " not used");
  }
}

// Positioning runs give their components; circles their squareness (used with an
// uncertainty only); the others are named as not used, runs with a critical flag as left out.
void fit_from_runs(const std::vector<std::string>& runs, const std::optional<std::string>& calibration,
                   const std::string& out, bool force) {
  namespace fs = std::filesystem;
  if (fs::exists(out) && !force) throw dsp::InputError("volumetric: " + out + " exists (--force to replace it)");
  FitInputs in;
  for (const auto& path : runs) take_run(path, calibration, in);
  if (in.passes.empty() && !in.left_out.empty()) {
    std::string why;
    for (const auto& l : in.left_out) why += "\n  " + l;
    throw dsp::InputError("volumetric: no usable positioning run to fit the model from:" + why);
  }
  const dsp::comp::VolumetricFit f = dsp::comp::fit_volumetric(in.passes, in.circles);
  std::vector<std::string> sources = in.used;
  sources.insert(sources.end(), in.left_out.begin(), in.left_out.end());
  write_file_atomic(out, volumetric_model_toml(f, sources));
  std::printf("volumetric fit -> %s%s\n", out.c_str(),
              calibration ? (" (sensors: " + *calibration + ")").c_str() : " (sensors: the runs' data sheet)");
  for (const auto& u : sources) std::printf("  %s\n", u.c_str());
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
    std::string model, points, out, calibration;
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
  auto* cal = cmd->add_option("--calibration", o->calibration,
                              "with --fit: sensor calibration (eical-sensor-cal/1, from eical identify) instead of "
                              "the runs' data sheet, applied to every run")
                  ->check(CLI::ExistingFile);
  fit->excludes(model)->excludes(points);
  cal->needs(fit);
  cmd->callback([o] {
    if (!o->fit.empty()) {
      fit_from_runs(o->fit, o->calibration.empty() ? std::nullopt : std::optional(o->calibration), o->out, o->force);
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
