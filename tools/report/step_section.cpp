// Step response page (cross-grid encoder practice): position and set-point over time,
// each move's arrival overlaid (measured − target against time since arrival), the
// figures beside, one row per move below.
#include "dsp/core/axes.hpp"
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

#include <algorithm>
#include <cmath>

namespace eical::tools::report {

void step_sections(const dsp::Run&, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  if (!a.step) return;
  const auto& st = *a.step;
  const auto& m = a.measurement;
  const int ax = std::max(0, dsp::axis_index(a.step_axis));
  Section s;
  s.heading = "Step response (axis " + a.step_axis + ")";
  s.lead =
      std::to_string(st.moves.size()) + " moves; each judged from its arrival at the target to the end of its dwell.";
  std::vector<double> t, pos, cmd, err;
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    t.push_back(static_cast<double>(m.sample_index[i]) / m.fs_hz);
    pos.push_back(m.pos_mm[i][ax]);
    cmd.push_back(m.cmd_mm[i][ax]);
    err.push_back((m.pos_mm[i][ax] - m.cmd_mm[i][ax]) * 1000.0);
  }
  s.svgs.push_back(line_plot({{"set-point", kGrey, t, cmd, {}, {}, false, true, 1.4}, {"measured", kBlue, t, pos}},
                             "Position over time", "time (s)", "position " + a.step_axis + " (mm)", 680, 250));
  s.svgs.push_back(
      line_plot({{"measured − set-point", kBlue, t, err}}, "Following error", "time (s)", "error (µm)", 680, 220));
  // Arrivals overlaid, from the moment the set-point stops to the end of the dwell: what
  // remains is the machine settling (and the measurement), not the move itself.
  const char* colors[] = {kBlue, kRed, kGreen, "#8e44ad", "#d35400", "#16a085", "#2c3e50", "#b7950b"};
  std::vector<LineSeries> arrivals;
  for (std::size_t k = 0; k < st.moves.size() && k < 8; ++k) {
    const auto& mv = st.moves[k];
    LineSeries ls{fmt("%.3f", mv.from_mm) + " → " + fmt("%.3f", mv.to_mm) + " mm", colors[k], {}, {}};
    for (std::size_t i = mv.arrive; i < mv.end && i < pos.size(); ++i) {
      ls.x.push_back(static_cast<double>(static_cast<std::int64_t>(i) - static_cast<std::int64_t>(mv.arrive)) /
                     m.fs_hz);
      ls.y.push_back((pos[i] - mv.to_mm) * 1000.0);
    }
    arrivals.push_back(std::move(ls));
  }
  s.svgs.push_back(line_plot(arrivals, "Arrival at the target (moves overlaid)", "time since the set-point arrived (s)",
                             "measured − target (µm)", 680, 280));
  const FigureRows fr(a);
  Table f{"Step figures (± U, k = 2)", {}};
  f.rows = {fr.row("step.end_position_error_um", "End-position error (mean)", "µm", 2, "measured − commanded"),
            fr.row("step.scatter_um", "Scatter over repeats", "µm", 2, "pooled s, same target and direction"),
            fr.row("step.overshoot_um", "Overshoot (max)", "µm", 2),
            fr.row("step.settling_s", "Settling time (max)", "ms", 1, "into ±1 µm of the end value", 1000.0),
            fr.row("step.noise_um", "Noise in the dwell", "µm", 3, "RMS, median over dwells"),
            {"Smallest step resolved",
             st.smallest_step_resolved_um > 0 ? std::optional<double>(st.smallest_step_resolved_um) : std::nullopt,
             "µm", 1, st.smallest_step_resolved_um > 0 ? "" : "no step resolved"}};
  s.tables.push_back(f);
  Grid g{
      "Per move",
      {"move", "from → to (mm)", "step measured (µm)", "end error (µm)", "overshoot (µm)", "settling (ms)", "resolved"},
      {}};
  for (std::size_t k = 0; k < st.moves.size(); ++k) {
    const auto& mv = st.moves[k];
    g.rows.push_back({std::to_string(k + 1), fmt("%.3f", mv.from_mm) + " → " + fmt("%.3f", mv.to_mm),
                      fmt("%.2f", mv.step_measured_um), fmt("%.2f", mv.end_error_um), fmt("%.2f", mv.overshoot_um),
                      mv.settled ? fmt("%.1f", mv.settling_s * 1000.0) : "not settled", mv.resolved ? "yes" : "no"});
  }
  s.grids.push_back(g);
  page.sections.push_back(std::move(s));
  csv.write("trace_step.csv", {"t_s", "position_mm", "setpoint_mm", "error_um"}, {t, pos, cmd, err});
}

}  // namespace eical::tools::report
