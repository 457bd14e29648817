#include "tools/comp/fanuc_export.hpp"

#include "dsp/core/error.hpp"

#include <cmath>
#include <cstdio>
#include <map>

namespace eical::tools::comp {
namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::string param(int number, const std::map<int, long long>& per_axis) {
  char b[16];
  std::snprintf(b, sizeof b, "N%05d", number);
  std::string s = b;
  for (const auto& [axis, v] : per_axis) s += "A" + std::to_string(axis) + "P" + std::to_string(v);
  return s + "\n";
}

}  // namespace

std::vector<OutputFile> fanuc_outputs(const std::vector<AxisProposal>& axes, const FanucOptions& o) {
  if (!(o.detection_unit_um > 0.0)) throw dsp::InputError("comp: the FANUC detection unit must be positive");
  std::map<int, long long> p1851, p3620, p3621, p3622, p3623, p3624;
  std::string table =
      "; eical comp: FANUC pitch error compensation data for the PITCH ERROR COMPENSATION screen\n"
      "; value = increment of the compensation amount (added to the command, = -deviation) over the section\n"
      "; that ends at the point, in detection units of " +
      fmt("%g", o.detection_unit_um) + " um; the amount is 0 at the reference position\n";
  int next_number = o.first_point_number;
  for (const auto& p : axes) {
    const int a = p.axis + 1;  // controlled axis number: X 1, Y 2, Z 3
    const auto units = [&](double um) { return std::llround(um / o.detection_unit_um); };
    std::optional<double> b = p.lost_motion_um;
    if (p.table) {
      const dsp::comp::AxisTable mean = dsp::comp::without_reversal(*p.table);
      b = p.table->mean_lost_motion_um();
      const long long step_units = std::max(1LL, units(grid_spacing_mm(mean, o.grid) * 1e3));
      const double step_mm = static_cast<double>(step_units) * o.detection_unit_um * 1e-3;
      // Points at reference + k·interval, covering the measured range and the reference.
      const long long k_min =
          std::min(0LL, static_cast<long long>(std::floor((mean.first_mm() - o.reference_mm) / step_mm + 1e-9)));
      const long long k_max =
          std::max(0LL, static_cast<long long>(std::ceil((mean.last_mm() - o.reference_mm) / step_mm - 1e-9)));
      if (k_max - k_min > 1023)
        throw dsp::InputError("comp: the FANUC table would need more than 1024 points: give a larger --spacing-mm");
      const double c_ref = mean.correction_um(o.reference_mm, dsp::comp::Approach::forward);
      const int n_min = next_number;
      const int n_ref = n_min + static_cast<int>(-k_min);
      p3620[a] = n_ref, p3621[a] = n_min, p3622[a] = n_min + static_cast<int>(k_max - k_min), p3623[a] = 1,
      p3624[a] = step_units;
      table += "; axis " + std::string(1, dsp::comp::axis_letter(p.axis)) + " (A" + std::to_string(a) +
               "): " + p.source + "\n;   No.    to_mm       value\n";
      long long prev = 0;
      for (long long k = k_min; k <= k_max; ++k) {
        const double pos = o.reference_mm + static_cast<double>(k) * step_mm;
        // Rounded cumulatively: the amount at every point is within half a unit.
        const long long amount = units(mean.correction_um(pos, dsp::comp::Approach::forward) - c_ref);
        const long long value = k == k_min ? 0 : amount - prev;
        prev = amount;
        char line[96];
        std::snprintf(line, sizeof line, "%6lld  %10.4f  %+6lld\n", static_cast<long long>(n_min) + (k - k_min), pos,
                      value);
        table += line;
      }
      next_number = static_cast<int>(p3622[a]) + 1;
    }
    if (b) p1851[a] = units(*b);
  }
  std::vector<OutputFile> out;
  if (!p3620.empty() || !p1851.empty()) {
    std::string tape = "%\n";
    if (!p1851.empty()) tape += param(1851, p1851);
    if (!p3620.empty())
      tape += param(3620, p3620) + param(3621, p3621) + param(3622, p3622) + param(3623, p3623) + param(3624, p3624);
    tape += "%\n";
    out.push_back({"fanuc/parameters.txt", tape});
  }
  if (!p3620.empty()) out.push_back({"fanuc/pitch_error_table.txt", table});
  return out;
}

}  // namespace eical::tools::comp
