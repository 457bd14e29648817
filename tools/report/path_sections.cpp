// Rectangle and free-form pages: the path in its plane with the deviation magnified, the
// contour deviation along the path, and the corner / contour figures.
#include "tools/report/sections.hpp"

#include "dsp/analysis/figures.hpp"
#include "tools/report/svg.hpp"

namespace eical::tools::report {
namespace {

// The plane view and the along-path plot of a path deviation, and its CSV.
void path_plots(const dsp::Analysis& a, int ia, int ib, const std::string& na, const std::string& nb, Section& s,
                CsvFiles& csv, const std::string& csv_name, PathView view) {
  const auto& m = a.measurement;
  for (std::size_t i = 0; i < m.sample_index.size(); ++i)
    view.cmd_a_mm.push_back(m.cmd_mm[i][ia]), view.cmd_b_mm.push_back(m.cmd_mm[i][ib]);
  // Only the contour-normal part is drawn magnified: the lag along the path does not
  // spoil the contour and would smear the picture at every corner.
  if (a.path)
    for (std::size_t k = 0; k < a.path->sample.size(); ++k) {
      const std::size_t i = a.path->sample[k];
      if (i == 0 || i + 1 >= m.cmd_mm.size()) continue;
      const Eigen::Vector2d t(m.cmd_mm[i + 1][ia] - m.cmd_mm[i - 1][ia], m.cmd_mm[i + 1][ib] - m.cmd_mm[i - 1][ib]);
      if (t.norm() <= 0.0) continue;
      // In-plane normal part of measured − set-point (any plane; the path deviation's own
      // sign convention is for XY paths).
      const Eigen::Vector2d nrm = Eigen::Vector2d(-t.y(), t.x()).normalized();
      const Eigen::Vector2d d_um((m.pos_mm[i][ia] - m.cmd_mm[i][ia]) * 1000.0,
                                 (m.pos_mm[i][ib] - m.cmd_mm[i][ib]) * 1000.0);
      const Eigen::Vector2d left = nrm * nrm.dot(d_um);
      view.base_a_mm.push_back(m.cmd_mm[i][ia]), view.base_b_mm.push_back(m.cmd_mm[i][ib]);
      view.dev_a_um.push_back(left.x()), view.dev_b_um.push_back(left.y());
    }
  s.svgs.push_back(path_plot(view, "Path in the " + na + nb + " plane", na, nb));
  if (!a.path) return;
  const auto& d = *a.path;
  s.svgs.push_back(
      line_plot({{"normal (contour) deviation", kBlue, d.arc_length_mm, d.normal_um},
                 {"tangential (lag, + ahead)", kGrey, d.arc_length_mm, d.tangential_um, {}, {}, false, true, 1.0}},
                "Deviation along the path", "path length (mm)", "deviation (µm)", 680, 260));
  std::vector<double> sample(d.sample.begin(), d.sample.end()), t;
  for (auto i : d.sample) t.push_back(static_cast<double>(m.sample_index[i]) / m.fs_hz);
  csv.write(csv_name, {"t_s", "arc_length_mm", "normal_um", "normal_magnitude_um", "tangential_um"},
            {t, d.arc_length_mm, d.normal_um, d.normal_magnitude_um, d.tangential_um});
}

Table path_table(const dsp::Analysis& a, const std::string& prefix) {
  const FigureRows fr(a);
  const auto& d = *a.path;
  return {"Contour deviation (± U, k = 2)",
          {fr.row(prefix + ".contour_error_max_um", "Contour error (max)", "µm", 2, "normal to the path"),
           fr.row(prefix + ".contour_error_rms_um", "Contour error (RMS)", "µm", 2),
           fr.row(prefix + ".tangential_rms_um", "Tangential deviation (RMS)", "µm", 2, "lag along the path"),
           {"Path length evaluated",
            d.arc_length_mm.empty() ? std::nullopt : std::optional<double>(d.arc_length_mm.back()), "mm", 1, ""}}};
}

}  // namespace

void rectangle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  if (!a.rectangle && !a.path) return;
  const auto [ia, ib] = dsp::plane_axes(run.meta.program.plane);
  const auto [na, nb] = plane_axis_names(run.meta.program.plane);
  Section s;
  s.heading = "Rectangle";
  s.lead =
      "Exact stop at every corner: corner position errors, side straightness and corner angles, and the contour "
      "between.";
  PathView view;
  if (a.rectangle)
    for (std::size_t k = 0; k < a.rectangle->corners_mm.size(); ++k) {
      view.arrow_a_mm.push_back(a.rectangle->corners_mm[k].x()),
          view.arrow_b_mm.push_back(a.rectangle->corners_mm[k].y());
      view.arrow_da_um.push_back(a.rectangle->corner_errors_um[k].x()),
          view.arrow_db_um.push_back(a.rectangle->corner_errors_um[k].y());
    }
  path_plots(a, ia, ib, na, nb, s, csv, "trace_rectangle_path.csv", view);
  if (a.path) s.tables.push_back(path_table(a, "rectangle.path_deviation"));
  if (a.rectangle) {
    const auto& r = *a.rectangle;
    const FigureRows fr(a);
    s.tables.push_back(
        {"Rectangle (± U, k = 2)",
         {fr.row("rectangle.corner_error_max_um", "Largest corner error", "µm", 2, "|(error a, error b)|")}});
    auto pm = [&](std::size_t i, double v) {
      return fmt("%.2f", v) +
             (fr.u("rectangle.corner_errors_um", i) ? " ± " + fmt("%.2f", *fr.u("rectangle.corner_errors_um", i)) : "");
    };
    Grid g{"Corners (in the order visited, ± U)",
           {"stop", na + " (mm)", nb + " (mm)", "error " + na + " (µm)", "error " + nb + " (µm)"},
           {}};
    std::vector<double> ca, cb, ea, eb;
    for (std::size_t k = 0; k < r.corners_mm.size(); ++k) {
      g.rows.push_back({std::to_string(k + 1), fmt("%.3f", r.corners_mm[k].x()), fmt("%.3f", r.corners_mm[k].y()),
                        pm(2 * k, r.corner_errors_um[k].x()), pm(2 * k + 1, r.corner_errors_um[k].y())});
      ca.push_back(r.corners_mm[k].x()), cb.push_back(r.corners_mm[k].y()), ea.push_back(r.corner_errors_um[k].x()),
          eb.push_back(r.corner_errors_um[k].y());
    }
    s.grids.push_back(g);
    Grid sides{"Sides",
               {"side", "from → to (mm)", "straightness (µm)", "direction error (µrad)", "angle to next side (µrad)"},
               {}};
    const auto assumed = [&](const char* key) { return a.not_evaluated.count(key) > 0; };
    const bool direction_assumed = assumed(dsp::kRectangleDirectionKey);
    const bool angle_assumed = assumed(dsp::kRectangleCornerAngleKey);
    const bool straightness_assumed = assumed(dsp::kRectangleStraightnessKey);
    for (std::size_t k = 0; k < r.sides.size(); ++k) {
      const auto& sd = r.sides[k];
      sides.rows.push_back(
          {std::to_string(k + 1),
           "(" + fmt("%.2f", sd.from_mm.x()) + ", " + fmt("%.2f", sd.from_mm.y()) + ") → (" +
               fmt("%.2f", sd.to_mm.x()) + ", " + fmt("%.2f", sd.to_mm.y()) + ")",
           straightness_assumed ? "—" : fmt("%.2f", sd.straightness_um),
           direction_assumed ? "—" : fmt("%.1f", sd.direction_error_urad),
           !angle_assumed && k < r.corner_angle_error_urad.size() ? fmt("%.1f", r.corner_angle_error_urad[k]) : "—"});
    }
    for (const char* key : dsp::kRectangleAcrossSideKeys)  // one reason for the three: said once
      if (assumed(key)) {
        s.notes.push_back("Not evaluated: " + a.not_evaluated.at(key) + ".");
        break;
      }
    s.grids.push_back(sides);
    csv.write("trace_rectangle_corners.csv", {"corner_a_mm", "corner_b_mm", "error_a_um", "error_b_um"},
              {ca, cb, ea, eb});
  }
  s.notes.push_back(
      "Corner error = mean of measured − set-point over the stop. Straightness about the side's least-squares "
      "line (ISO 230-1), 10 % of each side's ends left out (acceleration).");
  page.sections.push_back(std::move(s));
}

void freeform_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  if (!a.path) return;
  const auto [ia, ib] = dsp::plane_axes(run.meta.program.plane);
  const auto [na, nb] = plane_axis_names(run.meta.program.plane);
  Section s;
  s.heading = "Free-form contour";
  s.lead =
      "Deviation of the measured path from the set-point path, split into the part normal to the path (what the "
      "workpiece sees) and the part along it (lag).";
  path_plots(a, ia, ib, na, nb, s, csv, "trace_freeform.csv", {});
  s.tables.push_back(path_table(a, "freeform"));
  s.notes.push_back(
      "Each measured point is matched to the closest point of the set-point polyline within ±0.2 s, so a path "
      "that crosses itself is not matched to the wrong pass; points slower than 0.5 mm/s are left out.");
  page.sections.push_back(std::move(s));
}

}  // namespace eical::tools::report
