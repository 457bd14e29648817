#include "tools/comp/sinumerik_export.hpp"

#include "dsp/core/error.hpp"

#include <cstdio>

namespace eical::tools::comp {
namespace {

std::string num(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

std::vector<OutputFile> sinumerik_outputs(const std::vector<AxisProposal>& axes, const SinumerikOptions& o) {
  std::string eec =
      "%_N_AX_EEC_INI\nCHANDATA(1)\n"
      "; eical comp: measuring system error compensation (K3 4.4.2), value = deviation (actual - nominal) in mm,\n"
      "; the bidirectional mean; the lost motion is in MD32450 (sinumerik/backlash.txt)\n";
  std::string backlash =
      "; eical comp: MD32450 $MA_BACKLASH[0] per axis (mm), positive when the encoder leads the machine part\n"
      "; (normal play). Enter in the axis machine data; with an MSEC table the mean lost motion of its positioning "
      "run.\n";
  bool any_table = false, any_backlash = false;
  for (const auto& p : axes) {
    if (p.axis < 0 || p.axis >= static_cast<int>(o.axis_names.size()))
      throw dsp::InputError("comp: no SINUMERIK axis name for axis " + std::string(1, dsp::comp::axis_letter(p.axis)) +
                            " (--sinumerik-axes)");
    const std::string& ax = o.axis_names[static_cast<std::size_t>(p.axis)];
    std::optional<double> b = p.lost_motion_um;
    if (p.table) {
      const dsp::comp::AxisTable g = dsp::comp::without_reversal(equidistant(*p.table, o.grid));
      b = p.table->mean_lost_motion_um();
      eec += "; " + std::string(1, dsp::comp::axis_letter(p.axis)) + " (" + ax + "): " + p.source +
             "; needs MD38000 $MA_MM_ENC_COMP_MAX_POINTS >= " + std::to_string(g.pos_mm.size()) + "\n";
      for (std::size_t i = 0; i < g.pos_mm.size(); ++i)
        eec += "$AA_ENC_COMP[0," + std::to_string(i) + "," + ax + "]=" + num("%.6f", g.forward_um[i] * 1e-3) + " ; " +
               num("%.4f", g.pos_mm[i]) + " mm\n";
      const double step = g.pos_mm.size() > 1 ? g.pos_mm[1] - g.pos_mm[0] : 0.0;
      eec += "$AA_ENC_COMP_STEP[0," + ax + "]=" + num("%.6f", step) + "\n";
      eec += "$AA_ENC_COMP_MIN[0," + ax + "]=" + num("%.6f", g.first_mm()) + "\n";
      eec += "$AA_ENC_COMP_MAX[0," + ax + "]=" + num("%.6f", g.last_mm()) + "\n";
      eec += "$AA_ENC_COMP_IS_MODULO[0," + ax + "]=0\n";
      any_table = true;
    }
    if (b) {
      backlash += "$MA_BACKLASH[0," + ax + "]=" + num("%.6f", *b * 1e-3) + " ; " +
                  std::string(1, dsp::comp::axis_letter(p.axis)) + ": " + p.source + "\n";
      any_backlash = true;
    }
  }
  eec += "M17\n";
  std::vector<OutputFile> out;
  if (any_table) out.push_back({"sinumerik/AX_EEC.INI", eec});
  if (any_backlash) out.push_back({"sinumerik/backlash.txt", backlash});
  return out;
}

}  // namespace eical::tools::comp
