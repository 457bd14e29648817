// eical comp RUN...: compensation proposals for the control from measured runs — the
// circle's backlash, squareness and scale mismatch, and pitch tables (forward/reverse)
// from positioning runs — written as LinuxCNC INI settings and compensation files.
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/comp/lincomp.hpp"
#include "tools/commands.hpp"
#include "tools/run_files.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace eical::tools {

void register_comp(CLI::App& app) {
  struct Opt {
    std::vector<std::string> runs;
    std::string out = "comp";
    double spacing = 0.0;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("comp", "Propose compensation (backlash, pitch tables, squareness, scale) from measured runs");
  cmd->add_option("runs", o->runs, "run directories (circle and positioning runs)")->required();
  cmd->add_option("-o,--out", o->out, "output folder")->default_val("comp");
  cmd->add_option("--spacing-mm", o->spacing, "resample pitch tables to this spacing (default: the measured targets)");
  cmd->callback([o] {
    namespace fs = std::filesystem;
    nlohmann::json j = {{"format", "eical-comp/1"}, {"runs", o->runs}};
    std::string ini = "# eical comp: proposed LinuxCNC settings (merge into the machine's INI file)\n";
    std::vector<std::pair<std::string, std::string>> files;  // name, text
    int n_circle = 0, n_pos = 0;
    for (const auto& path : o->runs) {
      const dsp::Run run = drivers::read_run(path);
      const dsp::Analysis a = dsp::analyze_run(run);
      if (a.diagnostics) {
        const auto& d = *a.diagnostics;
        ++n_circle;
        j["circle"][run.meta.id] = {{"backlash_x_um", d.backlash_x_um},
                                    {"backlash_y_um", d.backlash_y_um},
                                    {"squareness_xwy_urad", d.squareness_urad},
                                    {"scale_mismatch_ppm", d.scale_mismatch_ppm},
                                    {"cyclic_error_x_um", d.cyclic_error_x_um},
                                    {"cyclic_error_y_um", d.cyclic_error_y_um},
                                    {"cyclic_pitch_mm", d.cyclic_pitch_mm}};
        char b[512];
        std::snprintf(b, sizeof b,
                      "# from circle run %s\n[JOINT_0]\nBACKLASH = %.6f\n[JOINT_1]\nBACKLASH = %.6f\n"
                      "# squareness X-Y %.1f urad and scale mismatch X-Y %.1f ppm: enter as xwy and a linear\n"
                      "# term in eical-volumetric/1 (no INI key in LinuxCNC's trivial kinematics)\n",
                      run.meta.id.c_str(), std::max(0.0, d.backlash_x_um) / 1000.0, std::max(0.0, d.backlash_y_um) / 1000.0,
                      d.squareness_urad, d.scale_mismatch_ppm);
        ini += b;
      }
      if (a.positioning && a.positioning_input) {
        ++n_pos;
        const auto& p = *a.positioning;
        const std::string axis = p.axis;
        dsp::comp::ErrorCurve up, down;
        for (const auto& t : p.targets) {
          up.pos_mm.push_back(t.target_mm), up.error_um.push_back(t.mean_up_um);
          down.pos_mm.push_back(t.target_mm), down.error_um.push_back(t.mean_down_um);
        }
        const double spacing = o->spacing > 0 ? o->spacing : (up.pos_mm.back() - up.pos_mm.front()) / static_cast<double>(up.pos_mm.size() - 1);
        const auto tu = dsp::comp::correction_table(up, up.pos_mm.front(), spacing);
        const auto td = dsp::comp::correction_table(down, down.pos_mm.front(), spacing);
        std::string text = "# eical comp: axis " + axis + " from run " + run.meta.id + "; COMP_FILE_TYPE = 0 (nominal forward reverse, mm)\n";
        nlohmann::json table = nlohmann::json::array();
        for (std::size_t i = 0; i < tu.pos_mm.size(); ++i) {
          char line[128];
          std::snprintf(line, sizeof line, "%.4f %.6f %.6f\n", tu.pos_mm[i], tu.pos_mm[i] - tu.correction_um[i] / 1000.0,
                        td.pos_mm[i] - td.correction_um[i] / 1000.0);
          text += line;
          table.push_back({{"pos_mm", tu.pos_mm[i]}, {"forward_deviation_um", tu.correction_um[i]}, {"reverse_deviation_um", td.correction_um[i]}});
        }
        const std::string name = "axis_" + axis + ".comp";
        files.emplace_back(name, text);
        const int joint = axis == "x" ? 0 : axis == "y" ? 1 : 2;
        ini += "# from positioning run " + run.meta.id + " (ISO 230-2 A " + std::to_string(p.A_um) + " um)\n[JOINT_" + std::to_string(joint) +
               "]\nCOMP_FILE = " + name + "\nCOMP_FILE_TYPE = 0\n";
        j["positioning"][run.meta.id] = {{"axis", axis}, {"A_um", p.A_um}, {"B_mean_um", p.B_mean_um}, {"spacing_mm", spacing}, {"table", table}, {"file", name}};
      }
      if (!a.diagnostics && !a.positioning)
        j["skipped"].push_back({{"run", path}, {"reason", "program '" + run.meta.program.kind + "' gives no compensation terms"}});
    }
    if (n_circle == 0 && n_pos == 0) throw std::runtime_error("comp: none of the runs is a circle or positioning run that could be evaluated");
    fs::create_directories(o->out);
    for (const auto& [name, text] : files) write_file_atomic(fs::path(o->out) / name, text);
    write_file_atomic(fs::path(o->out) / "linuxcnc.ini", ini);
    write_file_atomic(fs::path(o->out) / "comp.json", j.dump(2) + "\n");
    std::printf("comp: %d circle and %d positioning runs -> %s (linuxcnc.ini, comp.json%s)\n", n_circle, n_pos, o->out.c_str(),
                files.empty() ? "" : ", axis tables");
  });
}

}  // namespace eical::tools
