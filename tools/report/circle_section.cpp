// Circular test page: the ballbar-style polar plot (both directions) with the ISO 230-4
// figures and the diagnostics beside it.
#include "tools/report/sections.hpp"
#include "tools/report/svg.hpp"

namespace eical::tools::report {

void circle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  if (!a.circle) return;
  const auto& c = *a.circle;
  const auto& p = run.meta.program;
  const auto [na, nb] = plane_axis_names(p.plane);
  const bool partial = c.arc_deg < 360.0;
  Section s;
  s.heading = partial ? "Circular test (ISO 230-4), " + fmt("%.0f", c.arc_deg) + "° partial arc" : "Circular test (ISO 230-4)";
  s.lead = "Radius deviation along the path, both directions where measured; plot magnified about the reference circle as "
           "on a ballbar plot.";
  // One polyline per revolution (each has its own centre: joining them would draw a jump).
  std::vector<PolarTrace> polar;
  for (const char* dir : {"ccw", "cw"}) {
    const bool ccw = std::string(dir) == "ccw";
    bool labelled = false;
    for (int rev = 0; rev <= c.revolutions; ++rev) {
      PolarTrace t;
      t.color = ccw ? kBlue : kRed;
      for (std::size_t i = 0; i < c.trace.angle_deg.size(); ++i)
        if (c.trace.direction[i] == dir && c.trace.revolution[i] == rev)
          t.angle_deg.push_back(c.trace.angle_deg[i]), t.deviation_um.push_back(c.trace.radius_deviation_um[i]);
      if (t.angle_deg.empty()) continue;
      if (!labelled) t.label = ccw ? "counter-clockwise (G3)" : "clockwise (G2)", labelled = true;
      polar.push_back(std::move(t));
    }
  }
  s.svgs.push_back(polar_plot(polar, "Radius deviation, " + p.plane + " plane", "+" + na, "+" + nb));
  Table iso{"ISO 230-4 figures", {}};
  iso.rows = {{"Nominal radius", p.radius_mm, "mm", 3, ""},
              {"Feed", p.feed_mm_min, "mm/min", 0, ""},
              {partial ? "Arcs evaluated" : "Revolutions evaluated", static_cast<double>(c.revolutions), "", 0,
               c.direction == "both" ? "both directions" : c.direction},
              {"Mean radius deviation", c.radius_mean_deviation_um, "µm", 2, "measured − nominal"},
              {"Circular deviation G", c.circular_deviation_G_um, "µm", 2, partial ? "about the programmed centre" : "about the LSQ centre"},
              {"Circular hysteresis H", c.circular_hysteresis_H_um, "µm", 2, c.circular_hysteresis_H_um ? "max over 1° bins" : "needs both directions"},
              {"Radial deviation F max", c.radial_deviation_F_max_um, "µm", 2, ""},
              {"Radial deviation F min", c.radial_deviation_F_min_um, "µm", 2, ""}};
  s.tables.push_back(iso);
  if (a.diagnostics) {
    const auto& d = *a.diagnostics;
    const bool sep = d.servo_and_squareness_separated;
    Table dt{"Diagnostics (per axis)", {}};
    dt.rows = {{"Backlash " + na, d.backlash_x_um, "µm", 2, ""},
               {"Backlash " + nb, d.backlash_y_um, "µm", 2, ""},
               {"Reversal spike " + na, d.reversal_spike_x_um, "µm", 2, ""},
               {"Reversal spike " + nb, d.reversal_spike_y_um, "µm", 2, ""},
               {"Lateral play " + na, d.lateral_play_x_um, "µm", 2, ""},
               {"Lateral play " + nb, d.lateral_play_y_um, "µm", 2, ""},
               {"Cyclic error " + na, d.cyclic_error_x_um, "µm", 2, "pitch " + fmt("%.1f mm", d.cyclic_pitch_mm)},
               {"Cyclic error " + nb, d.cyclic_error_y_um, "µm", 2, ""},
               {"Servo mismatch", sep ? std::optional<double>(d.servo_mismatch_ms) : std::nullopt, "ms", 3,
                sep ? na + " lag − " + nb + " lag" : "needs both directions"},
               {"Squareness", d.squareness_urad, "µrad", 1, "+: angle above 90°"},
               {"Scale mismatch", d.scale_mismatch_ppm, "ppm", 1, na + " − " + nb},
               {"Straightness " + na, d.straightness_x_um, "µm", 2, ""},
               {"Straightness " + nb, d.straightness_y_um, "µm", 2, ""},
               {"Stick-slip", d.stick_slip_um, "µm", 2, "tangential, fast"},
               {"Vibration", d.vibration_um, "µm", 2, "radial, fast"}};
    s.tables.push_back(dt);
    for (const auto& n : d.notes) s.notes.push_back(n);
  } else {
    s.notes.push_back(partial ? "Diagnostics: not evaluated on a partial arc (they need full revolutions)."
                              : "Diagnostics: could not be determined (see the flags above).");
  }
  s.notes.push_back(partial ? "Partial arc: the radius is measured from the programmed centre (as a ballbar measures from its "
                              "pivot), because a centre fitted to a partial arc trades off against the radius. A real centre "
                              "offset therefore shows as a once-per-revolution term and enters G and F."
                            : "Each revolution is evaluated about its own least-squares centre (the integration drift of an "
                              "inertial measurement moves the centre slowly; a ballbar's pivot does the same job).");
  if (a.circle_reference && a.circle_accuracy_rms_um) {
    Table r{"Against the reference (" + (run.meta.reference ? run.meta.reference->kind : std::string("ref")) + ")", {}};
    r.rows = {{"Radius deviation error (RMS)", *a.circle_accuracy_rms_um, "µm", 3, "eical − reference"},
              {"Reference G", a.circle_reference->circular_deviation_G_um, "µm", 2, "same evaluation"},
              {"Reference mean radius deviation", a.circle_reference->radius_mean_deviation_um, "µm", 2, ""}};
    s.tables.push_back(r);
  }
  page.sections.push_back(std::move(s));
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

}  // namespace eical::tools::report
