// Circular test page: the ballbar-style polar plot (both directions) with the ISO 230-4
// figures and the diagnostics beside it.
#include "dsp/uncertainty/resolved.hpp"
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

#include <algorithm>
#include <cmath>

namespace eical::tools::report {

namespace {

// One trace per revolution of one direction, each its own colour, drawn as measured (not
// joined back to its start), a marker where it begins.
std::vector<PolarTrace> revolution_traces(const dsp::eval::CircleResult& c, bool partial, const std::string& dir) {
  std::vector<PolarTrace> polar;
  const bool ccw = dir == "ccw";
  for (int rev = 0; rev <= c.revolutions; ++rev) {
    PolarTrace t;
    t.color = revolution_colour(ccw, rev);
    for (std::size_t i = 0; i < c.trace.angle_deg.size(); ++i)
      if (c.trace.direction[i] == dir && c.trace.revolution[i] == rev)
        t.angle_deg.push_back(c.trace.angle_deg[i]), t.deviation_um.push_back(c.trace.radius_deviation_um[i]);
    if (t.angle_deg.empty()) continue;
    t.label =
        std::string(ccw ? "ccw (G3)" : "cw (G2)") + (partial ? ", arc " : ", revolution ") + std::to_string(rev + 1);
    t.start_marker = true;
    polar.push_back(std::move(t));
  }
  return polar;
}

// The key of G for one direction's plot: G per direction when both ran, else G.
std::string g_key(const dsp::eval::CircleResult& c, const std::string& dir) {
  return c.direction == "both" ? "circle.circular_deviation_G_" + dir + "_um" : "circle.circular_deviation_G_um";
}

// One polar plot per direction. A direction whose U(G) exceeds the whole range its trace
// spans has no shape the measurement resolves: it is drawn as the band of that U about the
// reference circle, with a note, not as a shape the reader would take for the machine's.
void polar_plots(const dsp::eval::CircleResult& c, const dsp::Program& p, const FigureRows& fr, bool partial,
                 Section& s) {
  const auto [na, nb] = plane_axis_names(p.plane);
  for (const char* direction : {"ccw", "cw"}) {
    const std::string dir = direction;
    auto traces = revolution_traces(c, partial, dir);
    if (traces.empty()) continue;
    double max_abs_um = 0.0;
    for (const auto& t : traces)
      for (double d : t.deviation_um)
        if (std::isfinite(d)) max_abs_um = std::max(max_abs_um, std::abs(d));
    const std::string key = g_key(c, dir);
    const auto g = fr.value(key), u = fr.u(key);
    const std::string name = dir == "ccw" ? "counter-clockwise (G3)" : "clockwise (G2)";
    const std::string subtitle =
        "G " + (g ? fmt("%.2f", *g) + (u ? " ± " + fmt("%.2f", *u) : "") + " µm" : std::string("n/a"));
    PolarBand band;
    if (u && std::isfinite(*u) && *u > 2.0 * max_abs_um) {
      band = {*u / 2.0, dir == "ccw" ? kBlue : kRed,
              "± U(G)/2 = ± " + fmt("%.1f", *u / 2.0) + " µm: shape not resolved"};
      s.notes.push_back("The " + name + " trace is drawn as the band of its uncertainty: U(G) = " + fmt("%.1f", *u) +
                        " µm exceeds the whole range the trace spans (" + fmt("%.1f", 2.0 * max_abs_um) +
                        " µm), so its shape is noise of the measurement, not the machine's.");
      traces.clear();
    }
    s.svgs.push_back(polar_plot(traces, "Radius deviation, " + name + ", " + p.plane + " plane", "+" + na, "+" + nb,
                                0.0, subtitle, band));
  }
}

Table iso230_4_table(const dsp::eval::CircleResult& c, const dsp::Program& p, const FigureRows& fr, bool partial) {
  Table iso{"ISO 230-4 figures (± U, k = 2)", {}};
  iso.rows = {{"Nominal radius", p.radius_mm, "mm", 3, ""},
              {"Feed", p.feed_mm_min, "mm/min", 0, ""},
              {partial ? "Arcs evaluated" : "Revolutions evaluated", static_cast<double>(c.revolutions), "", 0,
               c.direction == "both" ? "both directions" : c.direction},
              fr.row("circle.radius_mean_deviation_um", "Mean radius deviation", "µm", 2, "measured − nominal"),
              fr.row("circle.circular_deviation_G_um", "Circular deviation G", "µm", 2,
                     partial ? "about the programmed centre" : "about the LSQ centre")};
  if (c.direction == "both") {
    iso.rows.push_back(fr.row("circle.circular_deviation_G_ccw_um", "G, counter-clockwise", "µm", 2));
    iso.rows.push_back(fr.row("circle.circular_deviation_G_cw_um", "G, clockwise", "µm", 2));
  }
  const char* averaged[2][2] = {{"circle.averaged_revolution_G_ccw_um", "G of the averaged revolution, ccw"},
                                {"circle.averaged_revolution_G_cw_um", "G of the averaged revolution, cw"}};
  for (std::size_t d = 0; d < 2; ++d)
    if (std::isfinite(c.direction_averaged_G_um[d]))
      iso.rows.push_back(fr.row(averaged[d][0], averaged[d][1], "µm", 2, "mean per 1° over the revolutions"));
  Figure h = fr.row("circle.circular_hysteresis_H_um", "Circular hysteresis H", "µm", 2,
                    c.circular_hysteresis_H_um ? "max over 1° bins" : "needs both directions");
  iso.rows.push_back(h);
  iso.rows.push_back(fr.row("circle.radial_deviation_F_max_um", "Radial deviation F max", "µm", 2));
  iso.rows.push_back(fr.row("circle.radial_deviation_F_min_um", "Radial deviation F min", "µm", 2));
  return iso;
}

// The diagnostics per axis with their notes, or why there are none.
void diagnostics_table(const dsp::Analysis& a, const std::string& na, const std::string& nb, const FigureRows& fr,
                       bool partial, Section& s) {
  if (!a.diagnostics) {
    s.notes.push_back(partial ? "Diagnostics: not evaluated on a partial arc (they need full revolutions)."
                              : "Diagnostics: could not be determined (see the flags above).");
    return;
  }
  const auto& d = *a.diagnostics;
  const bool sep = d.servo_and_squareness_separated;
  Table dt{"Diagnostics (per axis, ± U)", {}};
  dt.rows = {fr.row("diagnostics.backlash_x_um", "Backlash " + na, "µm", 2),
             fr.row("diagnostics.backlash_y_um", "Backlash " + nb, "µm", 2),
             fr.row("diagnostics.reversal_spike_x_um", "Reversal spike " + na, "µm", 2),
             fr.row("diagnostics.reversal_spike_y_um", "Reversal spike " + nb, "µm", 2),
             fr.row("diagnostics.lateral_play_x_um", "Lateral play " + na, "µm", 2),
             fr.row("diagnostics.lateral_play_y_um", "Lateral play " + nb, "µm", 2),
             fr.row("diagnostics.cyclic_error_x_um", "Cyclic error " + na, "µm", 2,
                    "pitch " + fmt("%.1f mm", d.cyclic_pitch_mm)),
             fr.row("diagnostics.cyclic_error_y_um", "Cyclic error " + nb, "µm", 2),
             fr.row("diagnostics.servo_mismatch_ms", "Servo mismatch", "ms", 3,
                    sep ? na + " lag − " + nb + " lag" : "needs both directions"),
             fr.row("diagnostics.squareness_urad", "Squareness", "µrad", 1, "+: angle above 90°"),
             fr.row("diagnostics.scale_mismatch_ppm", "Scale mismatch", "ppm", 1, na + " − " + nb),
             fr.row("diagnostics.straightness_x_um", "Straightness " + na, "µm", 2),
             fr.row("diagnostics.straightness_y_um", "Straightness " + nb, "µm", 2),
             fr.row("diagnostics.stick_slip_um", "Stick-slip", "µm", 2, "tangential, fast"),
             fr.row("diagnostics.vibration_um", "Vibration", "µm", 2, "radial, fast")};
  s.tables.push_back(dt);
  for (const auto& n : d.notes) s.notes.push_back(n);
  s.notes.push_back(
      "A diagnostic whose magnitude is not above its uncertainty U is marked \"not resolved\": the measurement "
      "cannot tell it "
      "from zero, and eical comp never compensates it.");
}

// The diagnostics ranked by what each alone does to the circle, as a ballbar report ranks
// them: the radial range it draws on this radius and feed (squareness and scale mismatch an
// ellipse of range R·e, servo mismatch one of range v·Δτ, a cyclic error twice its
// amplitude, vibration 2√2 × its RMS, the steps their size), against G.
void contribution_grid(const dsp::Analysis& a, const dsp::Program& p, const FigureRows& fr, const std::string& na,
                       const std::string& nb, Section& s) {
  if (!a.diagnostics || !a.circle) return;
  const auto& d = *a.diagnostics;
  const double r_mm = p.radius_mm, v_mm_s = p.feed_mm_min / 60.0, g_um = a.circle->circular_deviation_G_um;
  struct Part {
    std::string name, key;
    double range_um;
  };
  std::vector<Part> parts = {
      {"Backlash " + na, "diagnostics.backlash_x_um", std::abs(d.backlash_x_um)},
      {"Backlash " + nb, "diagnostics.backlash_y_um", std::abs(d.backlash_y_um)},
      {"Reversal spike " + na, "diagnostics.reversal_spike_x_um", std::abs(d.reversal_spike_x_um)},
      {"Reversal spike " + nb, "diagnostics.reversal_spike_y_um", std::abs(d.reversal_spike_y_um)},
      {"Lateral play " + na, "diagnostics.lateral_play_x_um", std::abs(d.lateral_play_x_um)},
      {"Lateral play " + nb, "diagnostics.lateral_play_y_um", std::abs(d.lateral_play_y_um)},
      {"Cyclic error " + na, "diagnostics.cyclic_error_x_um", 2.0 * std::abs(d.cyclic_error_x_um)},
      {"Cyclic error " + nb, "diagnostics.cyclic_error_y_um", 2.0 * std::abs(d.cyclic_error_y_um)},
      {"Servo mismatch", "diagnostics.servo_mismatch_ms", v_mm_s * std::abs(d.servo_mismatch_ms)},
      {"Squareness", "diagnostics.squareness_urad", r_mm * std::abs(d.squareness_urad) * 1e-3},
      {"Scale mismatch", "diagnostics.scale_mismatch_ppm", r_mm * std::abs(d.scale_mismatch_ppm) * 1e-3},
      {"Straightness " + na, "diagnostics.straightness_x_um", std::abs(d.straightness_x_um)},
      {"Straightness " + nb, "diagnostics.straightness_y_um", std::abs(d.straightness_y_um)},
      {"Stick-slip", "diagnostics.stick_slip_um", std::abs(d.stick_slip_um)},
      {"Vibration", "diagnostics.vibration_um", 2.0 * std::sqrt(2.0) * std::abs(d.vibration_um)}};
  std::erase_if(parts, [](const Part& x) { return !std::isfinite(x.range_um); });
  std::stable_sort(parts.begin(), parts.end(), [](const Part& x, const Part& y) { return x.range_um > y.range_um; });
  Grid g{"What makes G: each diagnostic alone on this circle, largest first",
         {"diagnostic", "range it draws (µm)", "of G", "resolved"},
         {}};
  for (const auto& x : parts) {
    const auto u = fr.u(x.key, 0);
    const auto v = fr.value(x.key, 0);
    const bool resolved = u && v && dsp::uncertainty::resolved(*v, *u);
    g.rows.push_back({x.name, fmt("%.2f", x.range_um), g_um > 0.0 ? fmt("%.0f %%", 100.0 * x.range_um / g_um) : "",
                      resolved ? "yes" : "no"});
  }
  s.grids.push_back(g);
  s.notes.push_back(
      "The ranges overlap in angle and do not add up to G; a diagnostic not resolved may be noise of its size.");
}

// The same evaluation of the reference channel, when the run has one.
void reference_table(const dsp::Run& run, const dsp::Analysis& a, Section& s) {
  if (!a.circle_reference || !a.circle_accuracy_rms_um) return;
  Table r{"Against the reference (" + (run.meta.reference ? run.meta.reference->kind : std::string("ref")) + ")", {}};
  r.rows = {{"Radius deviation error (RMS)", *a.circle_accuracy_rms_um, "µm", 3, "eical − reference"},
            {"Reference G", a.circle_reference->circular_deviation_G_um, "µm", 2, "same evaluation"},
            {"Reference mean radius deviation", a.circle_reference->radius_mean_deviation_um, "µm", 2, ""}};
  s.tables.push_back(r);
}

// trace_circle.csv: the trace behind the polar plot (and the reference's beside it).
void circle_csv(const dsp::Analysis& a, CsvFiles& csv) {
  const auto& c = *a.circle;
  std::vector<double> rev(c.trace.revolution.begin(), c.trace.revolution.end()), dir;
  for (const auto& d : c.trace.direction) dir.push_back(d == "cw" ? -1.0 : 1.0);
  std::vector<std::vector<double>> cols{c.trace.angle_deg, c.trace.radius_deviation_um, dir, rev};
  std::vector<std::string> head{"angle_deg", "radius_deviation_um", "direction_ccw1_cw-1", "revolution"};
  if (a.circle_reference && a.circle_reference->trace.radius_deviation_um.size() == c.trace.angle_deg.size()) {
    cols.push_back(a.circle_reference->trace.radius_deviation_um);
    head.emplace_back("reference_radius_deviation_um");
  }
  csv.write("trace_circle.csv", head, cols);
}

}  // namespace

void circle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  if (!a.circle) return;
  const auto& c = *a.circle;
  const auto& p = run.meta.program;
  const auto [na, nb] = plane_axis_names(p.plane);
  const bool partial = c.arc_deg < 360.0;
  Section s;
  s.heading =
      partial ? "Circular test (ISO 230-4), " + fmt("%.0f", c.arc_deg) + "° partial arc" : "Circular test (ISO 230-4)";
  s.lead =
      "Radius deviation along the path, one plot per direction, magnified about the reference circle as on a ballbar "
      "plot.";
  const FigureRows fr(a);
  polar_plots(c, p, fr, partial, s);
  s.tables.push_back(iso230_4_table(c, p, fr, partial));
  diagnostics_table(a, na, nb, fr, partial, s);
  contribution_grid(a, p, fr, na, nb, s);
  s.notes.push_back(
      partial ? "Partial arc: the radius is measured from the programmed centre (as a ballbar measures from its "
                "pivot), because a centre fitted to a partial arc trades off against the radius. A real centre "
                "offset therefore shows as a once-per-revolution term and enters G and F."
              : "Each revolution is evaluated about its own least-squares centre (the integration drift of an "
                "inertial measurement moves the centre slowly; a ballbar's pivot does the same job).");
  reference_table(run, a, s);
  page.sections.push_back(std::move(s));
  circle_csv(a, csv);
}

}  // namespace eical::tools::report
