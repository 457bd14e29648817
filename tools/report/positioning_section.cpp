// ISO 230-2 page: the laser interferometer's deviation plot (mean per target and
// direction with ±2s bands, every run's points) beside the A/E/M/R/B table.
#include "dsp/core/float_limits.hpp"
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

namespace eical::tools::report {

namespace {

using dsp::eval::PositioningInput;
using dsp::eval::PositioningResult;

// The laser interferometer's plot: mean per target and direction with ±2s bands, every
// run's points.
std::string deviation_plot(const PositioningResult& r, const PositioningInput& in) {
  LineSeries up{"mean ↑ ± 2s", kBlue, {}, {}, {}, {}, false, false, 1.6},
      down{"mean ↓ ± 2s", kRed, {}, {}, {}, {}, false, false, 1.6};
  LineSeries up_pts{"runs ↑", kBlue, {}, {}, {}, {}, true}, down_pts{"runs ↓", kRed, {}, {}, {}, {}, true};
  for (const auto& t : r.targets) {
    up.x.push_back(t.target_mm), up.y.push_back(t.mean_up_um);
    up.y_lo.push_back(t.mean_up_um - 2 * t.s_up_um), up.y_hi.push_back(t.mean_up_um + 2 * t.s_up_um);
    down.x.push_back(t.target_mm), down.y.push_back(t.mean_down_um);
    down.y_lo.push_back(t.mean_down_um - 2 * t.s_down_um), down.y_hi.push_back(t.mean_down_um + 2 * t.s_down_um);
  }
  for (std::size_t j = 0; j < in.up_um.size(); ++j)
    for (std::size_t i = 0; i < in.targets_mm.size(); ++i) {
      up_pts.x.push_back(in.targets_mm[i]), up_pts.y.push_back(in.up_um[j][i]);
      down_pts.x.push_back(in.targets_mm[i]), down_pts.y.push_back(in.down_um[j][i]);
    }
  return line_plot({up, down, up_pts, down_pts}, "Positioning deviation, axis " + r.axis, "target position (mm)",
                   "deviation (µm)", 680, 340);
}

// B per target with its U as a bar, and the mean B̄ with its U as a band: a variation of
// B along the axis that stays inside the bars is not one the measurement shows.
std::string reversal_plot(const PositioningResult& r, const FigureRows& fr) {
  LineSeries b{"B per target ± U", kGreen, {}, {}, {}, {}, true, false, 1.4, true};
  LineSeries mean{"mean B̄ ± U", kGrey, {}, {}, {}, {}, false, true, 1.2};
  const auto bm = fr.value("positioning.B_mean_um"), bu = fr.u("positioning.B_mean_um");
  for (std::size_t i = 0; i < r.targets.size(); ++i) {
    const auto& t = r.targets[i];
    const double u = fr.u("positioning.per_target.B_um", i).value_or(kNaN);
    b.x.push_back(t.target_mm), b.y.push_back(t.B_um), b.y_lo.push_back(t.B_um - u), b.y_hi.push_back(t.B_um + u);
    if (bm) {
      mean.x.push_back(t.target_mm), mean.y.push_back(*bm);
      mean.y_lo.push_back(*bm - bu.value_or(0.0)), mean.y_hi.push_back(*bm + bu.value_or(0.0));
    }
  }
  return line_plot({mean, b}, "Reversal value per target (bars and band: ± U, k = 2)", "target position (mm)", "B (µm)",
                   680, 220);
}

// The ISO 230-2 figures and VDI/DGQ 3441's, each ± U.
void figure_tables(const FigureRows& fr, Section& s) {
  Table t{"ISO 230-2 figures (± U, k = 2)", {}};
  t.rows = {fr.row("positioning.A_um", "Accuracy A", "µm", 2, "bidirectional"),
            fr.row("positioning.A_up_um", "Accuracy A↑", "µm", 2),
            fr.row("positioning.A_down_um", "Accuracy A↓", "µm", 2),
            fr.row("positioning.E_um", "Systematic deviation E", "µm", 2, "bidirectional"),
            fr.row("positioning.E_up_um", "Systematic deviation E↑", "µm", 2),
            fr.row("positioning.E_down_um", "Systematic deviation E↓", "µm", 2),
            fr.row("positioning.M_um", "Mean positional deviation M", "µm", 2),
            fr.row("positioning.R_um", "Repeatability R", "µm", 2, "bidirectional"),
            fr.row("positioning.R_up_um", "Repeatability R↑", "µm", 2),
            fr.row("positioning.R_down_um", "Repeatability R↓", "µm", 2),
            fr.row("positioning.B_um", "Reversal value B", "µm", 2, "max |Bi|"),
            fr.row("positioning.B_mean_um", "Mean reversal value B̄", "µm", 2)};
  s.tables.push_back(t);
  Table v{"VDI/DGQ 3441", {}};
  v.rows = {fr.row("positioning.vdi3441.P_um", "Positioning uncertainty P", "µm", 2),
            fr.row("positioning.vdi3441.Pa_um", "Position deviation Pa", "µm", 2),
            fr.row("positioning.vdi3441.U_um", "Reversal span U", "µm", 2),
            fr.row("positioning.vdi3441.Ps_um", "Position scatter Ps", "µm", 2)};
  s.tables.push_back(v);
}

Grid per_target_grid(const PositioningResult& r, const FigureRows& fr) {
  auto pm = [&](const char* key, std::size_t i) {
    const auto val = fr.value(key, i), unc = fr.u(key, i);
    return (val ? fmt("%.2f", *val) : std::string("n/a")) + (unc ? " ± " + fmt("%.2f", *unc) : "");
  };
  Grid g{"Per target (± U, k = 2)",
         {"target (mm)", "x̄↑ (µm)", "x̄↓ (µm)", "2s↑ (µm)", "2s↓ (µm)", "Bi (µm)", "Ri (µm)"},
         {}};
  for (std::size_t i = 0; i < r.targets.size(); ++i) {
    const auto& tg = r.targets[i];
    g.rows.push_back({fmt("%.3f", tg.target_mm), pm("positioning.per_target.mean_up_um", i),
                      pm("positioning.per_target.mean_down_um", i), fmt("%.2f", 2 * tg.s_up_um),
                      fmt("%.2f", 2 * tg.s_down_um), pm("positioning.per_target.B_um", i),
                      pm("positioning.per_target.R_um", i)});
  }
  return g;
}

// trace_positioning.csv (every run's deviations) and trace_positioning_targets.csv (the
// means and scatters per target).
void positioning_csv(const PositioningResult& r, const PositioningInput& in, CsvFiles& csv) {
  std::vector<double> tg, run_no, dir, dev;
  for (std::size_t j = 0; j < in.up_um.size(); ++j)
    for (std::size_t i = 0; i < in.targets_mm.size(); ++i) {
      tg.push_back(in.targets_mm[i]), run_no.push_back(static_cast<double>(j + 1)), dir.push_back(1.0),
          dev.push_back(in.up_um[j][i]);
      tg.push_back(in.targets_mm[i]), run_no.push_back(static_cast<double>(j + 1)), dir.push_back(-1.0),
          dev.push_back(in.down_um[j][i]);
    }
  csv.write("trace_positioning.csv", {"target_mm", "run", "direction_up1_down-1", "deviation_um"},
            {tg, run_no, dir, dev});
  std::vector<double> t_mm, mu, md, su, sd;
  for (const auto& x : r.targets)
    t_mm.push_back(x.target_mm), mu.push_back(x.mean_up_um), md.push_back(x.mean_down_um), su.push_back(x.s_up_um),
        sd.push_back(x.s_down_um);
  csv.write("trace_positioning_targets.csv", {"target_mm", "mean_up_um", "mean_down_um", "s_up_um", "s_down_um"},
            {t_mm, mu, md, su, sd});
}

}  // namespace

void positioning_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  (void)run;
  if (!a.positioning || !a.positioning_input) return;
  const auto& r = *a.positioning;
  const auto& in = *a.positioning_input;
  Section s;
  s.heading = "Positioning accuracy and repeatability (ISO 230-2), axis " + r.axis;
  s.lead = std::to_string(r.runs) + " bidirectional runs over " + std::to_string(r.targets.size()) +
           " targets; deviation = measured − target at each stop.";
  s.svgs.push_back(deviation_plot(r, in));
  const FigureRows fr(a);
  s.svgs.push_back(reversal_plot(r, fr));
  figure_tables(fr, s);
  if (r.runs < dsp::eval::kRunsPerTargetIso230_2)
    s.notes.push_back(std::to_string(r.runs) + " runs per target and direction: ISO 230-2 asks for " +
                      std::to_string(dsp::eval::kRunsPerTargetIso230_2) +
                      ". The figures are evaluated by its formulas but are outside the standard (s from fewer runs is "
                      "less certain).");
  s.grids.push_back(per_target_grid(r, fr));
  page.sections.push_back(std::move(s));
  positioning_csv(r, in, csv);
}

}  // namespace eical::tools::report
