// ISO 230-2 page: the laser interferometer's deviation plot (mean per target and
// direction with ±2s bands, every run's points) beside the A/E/M/R/B table.
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

namespace eical::tools::report {

void positioning_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  (void)run;
  if (!a.positioning || !a.positioning_input) return;
  const auto& r = *a.positioning;
  const auto& in = *a.positioning_input;
  Section s;
  s.heading = "Positioning accuracy and repeatability (ISO 230-2), axis " + r.axis;
  s.lead = std::to_string(r.runs) + " bidirectional runs over " + std::to_string(r.targets.size()) +
           " targets; deviation = measured − target at each stop.";
  LineSeries up{"mean ↑ ± 2s", kBlue, {}, {}, {}, {}, false, false, 1.6}, down{"mean ↓ ± 2s", kRed, {}, {}, {}, {}, false, false, 1.6};
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
  s.svgs.push_back(line_plot({up, down, up_pts, down_pts}, "Positioning deviation, axis " + r.axis, "target position (mm)",
                             "deviation (µm)", 680, 340));
  LineSeries b{"reversal value B", kGreen, {}, {}};
  for (const auto& t : r.targets) b.x.push_back(t.target_mm), b.y.push_back(t.B_um);
  s.svgs.push_back(line_plot({b}, "Reversal value per target", "target position (mm)", "B (µm)", 680, 220));
  Table t{"ISO 230-2 figures", {}};
  t.rows = {{"Accuracy A", r.A_um, "µm", 2, "bidirectional"},
            {"Accuracy A↑", r.A_up_um, "µm", 2, ""},
            {"Accuracy A↓", r.A_down_um, "µm", 2, ""},
            {"Systematic deviation E", r.E_um, "µm", 2, "bidirectional"},
            {"Systematic deviation E↑", r.E_up_um, "µm", 2, ""},
            {"Systematic deviation E↓", r.E_down_um, "µm", 2, ""},
            {"Mean positional deviation M", r.M_um, "µm", 2, ""},
            {"Repeatability R", r.R_um, "µm", 2, "bidirectional"},
            {"Repeatability R↑", r.R_up_um, "µm", 2, ""},
            {"Repeatability R↓", r.R_down_um, "µm", 2, ""},
            {"Reversal value B", r.B_um, "µm", 2, "max |Bi|"},
            {"Mean reversal value B̄", r.B_mean_um, "µm", 2, ""}};
  s.tables.push_back(t);
  Table v{"VDI/DGQ 3441", {}};
  v.rows = {{"Positioning uncertainty P", r.vdi.P_um, "µm", 2, ""},
            {"Position deviation Pa", r.vdi.Pa_um, "µm", 2, ""},
            {"Reversal span U", r.vdi.U_um, "µm", 2, ""},
            {"Position scatter Ps", r.vdi.Ps_um, "µm", 2, ""}};
  s.tables.push_back(v);
  Grid g{"Per target", {"target (mm)", "x̄↑ (µm)", "x̄↓ (µm)", "2s↑ (µm)", "2s↓ (µm)", "Bi (µm)", "Ri (µm)"}, {}};
  for (const auto& tg : r.targets)
    g.rows.push_back({fmt("%.3f", tg.target_mm), fmt("%.2f", tg.mean_up_um), fmt("%.2f", tg.mean_down_um), fmt("%.2f", 2 * tg.s_up_um),
                      fmt("%.2f", 2 * tg.s_down_um), fmt("%.2f", tg.B_um), fmt("%.2f", tg.R_um)});
  s.grids.push_back(g);
  page.sections.push_back(std::move(s));
  std::vector<double> tg, run_no, dir, dev;
  for (std::size_t j = 0; j < in.up_um.size(); ++j)
    for (std::size_t i = 0; i < in.targets_mm.size(); ++i) {
      tg.push_back(in.targets_mm[i]), run_no.push_back(static_cast<double>(j + 1)), dir.push_back(1.0), dev.push_back(in.up_um[j][i]);
      tg.push_back(in.targets_mm[i]), run_no.push_back(static_cast<double>(j + 1)), dir.push_back(-1.0), dev.push_back(in.down_um[j][i]);
    }
  csv.write("trace_positioning.csv", {"target_mm", "run", "direction_up1_down-1", "deviation_um"}, {tg, run_no, dir, dev});
  std::vector<double> t_mm, mu, md, su, sd;
  for (const auto& x : r.targets)
    t_mm.push_back(x.target_mm), mu.push_back(x.mean_up_um), md.push_back(x.mean_down_um), su.push_back(x.s_up_um), sd.push_back(x.s_down_um);
  csv.write("trace_positioning_targets.csv", {"target_mm", "mean_up_um", "mean_down_um", "s_up_um", "s_down_um"}, {t_mm, mu, md, su, sd});
}

}  // namespace eical::tools::report
