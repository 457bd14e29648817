#include "tools/comp/heidenhain_export.hpp"

#include <cctype>
#include <cstdio>

namespace eical::tools::comp {
namespace {

// A table line without the padding of its last column.
std::string rtrim(std::string s) {
  while (s.size() > 1 && s[s.size() - 2] == ' ') s.erase(s.size() - 2, 1);
  return s;
}

}  // namespace

std::vector<OutputFile> heidenhain_outputs(const std::vector<AxisProposal>& axes, const HeidenhainOptions& o) {
  std::vector<OutputFile> out;
  std::string cma_cols[3];
  std::string backlash = "; eical comp: MP_backLash per axis (mm), the lost motion b of axes without a .COM table\n";
  bool any_backlash = false;
  for (const auto& p : axes) {
    const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(dsp::comp::axis_letter(p.axis))));
    if (p.table) {
      const dsp::comp::AxisTable g = equidistant(*p.table, o.grid);
      const std::string name = std::string(1, up) + ".COM";
      char line[160];
      std::string t = "BEGIN " + name + " MM\n";
      std::snprintf(line, sizeof line, "%-6s %-14s %-14s %-14s\n", "NR", "AXISPOS", std::string(1, up).c_str(),
                    "BACKLASH");
      t += rtrim(line);
      for (std::size_t i = 0; i < g.pos_mm.size(); ++i) {
        std::snprintf(line, sizeof line, "%-6zu %+-14.4f %+-14.6f %+-14.6f\n", i, g.pos_mm[i], g.forward_um[i] * 1e-3,
                      g.reverse_um[i] * 1e-3);
        t += rtrim(line);
      }
      t += "[END]\n";
      out.push_back({"heidenhain/" + name, t});
      cma_cols[p.axis] = name;
    } else if (p.lost_motion_um) {
      char line[160];
      std::snprintf(line, sizeof line, "%c: MP_backLash = %.6f ; %s\n", up, *p.lost_motion_um * 1e-3, p.source.c_str());
      backlash += line;
      any_backlash = true;
    }
  }
  if (!cma_cols[0].empty() || !cma_cols[1].empty() || !cma_cols[2].empty()) {
    char line[160];
    std::string c = "BEGIN CONFIG.CMA\n";
    std::snprintf(line, sizeof line, "%-6s %-10s %-10s %-10s %-6s\n", "NR", "X", "Y", "Z", "ACTIVE");
    c += rtrim(line);
    std::snprintf(line, sizeof line, "%-6d %-10s %-10s %-10s %-6s\n", 0, cma_cols[0].c_str(), cma_cols[1].c_str(),
                  cma_cols[2].c_str(), "*");
    c += rtrim(line);
    out.push_back({"heidenhain/CONFIG.CMA", c + "[END]\n"});
  }
  if (any_backlash) out.push_back({"heidenhain/backlash.txt", backlash});
  return out;
}

}  // namespace eical::tools::comp
