// eical iso230-2: ISO 230-2 positioning figures from a deviation table or ecmc data.
#include "drivers/results/result_json.hpp"
#include "dsp/eval/positioning.hpp"
#include "tools/commands.hpp"
#include "tools/io/positioning_readers.hpp"

#include <cstdio>
#include <memory>

namespace eical::tools {

void register_iso230_2(CLI::App& app) {
  struct Opt {
    std::string deviations, ecmc, axis = "x";
    bool json = false, vdi = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd =
      app.add_subcommand("iso230-2", "ISO 230-2 positioning accuracy and repeatability (optionally VDI/DGQ 3441)");
  auto* a =
      cmd->add_option("--deviations", o->deviations, "CSV target_mm,run,direction,deviation_um (direction up|down)");
  auto* b = cmd->add_option("--ecmc", o->ecmc, "ecmc ISO 230-2 data (TGT_DATA / REF_DATA_FWD / REF_DATA_BWD, mm)");
  a->excludes(b);
  cmd->add_option("--axis", o->axis, "axis name for the report")->default_val("x");
  cmd->add_flag("--vdi3441", o->vdi, "add the VDI/DGQ 3441 figures P, Pa, U, Ps");
  cmd->add_flag("--json", o->json, "print the positioning object of eical-result/1");
  cmd->callback([o] {
    if (o->deviations.empty() && o->ecmc.empty()) throw CLI::ValidationError("iso230-2", "give --deviations or --ecmc");
    auto in = o->deviations.empty() ? read_ecmc_dat(o->ecmc) : read_deviation_csv(o->deviations);
    in.axis = o->axis;
    const auto r = dsp::eval::evaluate_positioning(in);
    if (o->json) {
      std::printf("%s\n", drivers::positioning_json(in, r, o->vdi).dump(2).c_str());
      return;
    }
    std::printf("ISO 230-2, axis %s: %zu targets x %d bidirectional runs\n", r.axis.c_str(), r.targets.size(), r.runs);
    std::printf("  A %.3f um (up %.3f, down %.3f)   E %.3f um (up %.3f, down %.3f)   M %.3f um\n", r.A_um, r.A_up_um,
                r.A_down_um, r.E_um, r.E_up_um, r.E_down_um, r.M_um);
    std::printf("  R %.3f um (up %.3f, down %.3f)   B %.3f um, mean reversal %.3f um\n", r.R_um, r.R_up_um, r.R_down_um,
                r.B_um, r.B_mean_um);
    if (o->vdi)
      std::printf("  VDI/DGQ 3441: P %.3f um, Pa %.3f um, U %.3f um, Ps %.3f um\n", r.vdi.P_um, r.vdi.Pa_um, r.vdi.U_um,
                  r.vdi.Ps_um);
    if (r.runs < dsp::eval::kRunsPerTargetIso230_2)
      std::printf(
          "  note: %d runs per target and direction, ISO 230-2 asks for %d: evaluated by its formulas, outside the "
          "standard\n",
          r.runs, dsp::eval::kRunsPerTargetIso230_2);
  });
}

}  // namespace eical::tools
