#include "tools/report/run_report.hpp"

#include "tools/report/html.hpp"
#include "tools/report/svg.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace eical::tools::report {
namespace fs = std::filesystem;
namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

void write_csv(const fs::path& file, const std::string& header, const std::vector<std::vector<double>>& cols) {
  std::ofstream os(file, std::ios::trunc);
  if (!os) throw std::runtime_error(file.string() + ": cannot write");
  os << header << "\n";
  const std::size_t n = cols.empty() ? 0 : cols[0].size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < cols.size(); ++c) os << (c ? "," : "") << fmt("%.6f", cols[c][i]);
    os << "\n";
  }
}

// Thins a trace to about `max_points` for plotting (the CSV keeps every point).
std::vector<std::size_t> thin(std::size_t n, std::size_t max_points) {
  std::vector<std::size_t> idx;
  const std::size_t step = std::max<std::size_t>(1, n / max_points);
  for (std::size_t i = 0; i < n; i += step) idx.push_back(i);
  return idx;
}

void circle_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, const fs::path& dir) {
  const auto& c = *a.circle;
  const auto& p = run.meta.program;
  Section s;
  s.heading = std::string("Circular test (ISO 230-4), ") + (c.direction == "ccw" ? "counter-clockwise (G3)" : c.direction == "cw" ? "clockwise (G2)" : "both directions");
  s.figures = {{"Nominal radius", p.radius_mm, "mm", 3, ""},
               {"Feed", p.feed_mm_min, "mm/min", 0, ""},
               {"Revolutions evaluated", static_cast<double>(c.revolutions), "", 0, "between the M102 marks"},
               {"Mean radius deviation", c.radius_mean_deviation_um, "µm", 2, "measured − nominal"},
               {"Circular deviation G", c.circular_deviation_G_um, "µm", 2, "max − min about the LSQ centre"},
               {"Radial deviation F max", c.radial_deviation_F_max_um, "µm", 2, ""},
               {"Radial deviation F min", c.radial_deviation_F_min_um, "µm", 2, ""}};
  if (c.circular_hysteresis_H_um) s.figures.push_back({"Circular hysteresis H", *c.circular_hysteresis_H_um, "µm", 2, ""});
  std::vector<PolarTrace> polar;
  const char* colors[] = {"#1f5fbf", "#c0392b", "#27ae60", "#8e44ad", "#d35400", "#16a085"};
  for (int rev = 0; rev < c.revolutions; ++rev) {
    PolarTrace t;
    t.label = "revolution " + std::to_string(rev + 1);
    t.color = colors[rev % 6];
    for (std::size_t i = 0; i < c.trace.angle_deg.size(); ++i)
      if (c.trace.revolution[i] == rev && i % 10 == 0) {
        t.angle_deg.push_back(c.trace.angle_deg[i]);
        t.deviation_um.push_back(c.trace.radius_deviation_um[i]);
      }
    polar.push_back(std::move(t));
  }
  s.svgs.push_back(polar_plot(polar, "Radius deviation (µm) — " + c.direction));
  s.notes.push_back("Each revolution is evaluated about its own least-squares centre (the integration drift of an inertial "
                    "measurement moves the centre slowly; a ballbar's pivot does the same job). Trace: trace_circle.csv.");
  page.sections.push_back(std::move(s));
  std::vector<double> rev(c.trace.revolution.begin(), c.trace.revolution.end());
  write_csv(dir / "trace_circle.csv", "angle_deg,radius_deviation_um,revolution", {c.trace.angle_deg, c.trace.radius_deviation_um, rev});

  if (a.diagnostics) {
    const auto& d = *a.diagnostics;
    Section ds;
    ds.heading = "Diagnostics (ballbar class, per axis)";
    ds.figures = {{"Backlash X", d.backlash_x_um, "µm", 2, ""},
                  {"Backlash Y", d.backlash_y_um, "µm", 2, ""},
                  {"Reversal spike X", d.reversal_spike_x_um, "µm", 2, ""},
                  {"Reversal spike Y", d.reversal_spike_y_um, "µm", 2, ""},
                  {"Lateral play X", d.lateral_play_x_um, "µm", 2, ""},
                  {"Lateral play Y", d.lateral_play_y_um, "µm", 2, ""},
                  {"Cyclic error X", d.cyclic_error_x_um, "µm", 2, "pitch " + fmt("%.1f mm", d.cyclic_pitch_mm)},
                  {"Cyclic error Y", d.cyclic_error_y_um, "µm", 2, ""},
                  {"Servo mismatch", d.servo_and_squareness_separated ? std::optional<double>(d.servo_mismatch_ms) : std::nullopt, "ms",
                   3, d.servo_and_squareness_separated ? "X lag − Y lag" : "needs both directions"},
                  {"Squareness", d.squareness_urad, "µrad", 1, "positive: angle X–Y above 90°"},
                  {"Scale mismatch", d.scale_mismatch_ppm, "ppm", 1, "X − Y"},
                  {"Straightness X", d.straightness_x_um, "µm", 2, ""},
                  {"Straightness Y", d.straightness_y_um, "µm", 2, ""},
                  {"Model residual (radial, RMS)", d.vibration_um, "µm", 2, "vibration and noise"},
                  {"Model residual (tangential, RMS)", d.stick_slip_um, "µm", 2, "stick-slip and noise"}};
    for (const auto& n : d.notes) ds.notes.push_back(n);
    page.sections.push_back(std::move(ds));
  }
  if (a.circle_reference && a.circle_accuracy_rms_um) {
    Section r;
    r.heading = "Compared with the reference (" + (run.meta.reference ? run.meta.reference->kind : std::string("ref")) + ")";
    r.figures = {{"Radius deviation error (RMS)", *a.circle_accuracy_rms_um, "µm", 2, "eical − reference, same evaluation"},
                 {"Reference circular deviation G", a.circle_reference->circular_deviation_G_um, "µm", 2, ""},
                 {"Reference mean radius deviation", a.circle_reference->radius_mean_deviation_um, "µm", 2, ""}};
    LineSeries meas{"eical", "#1f5fbf", {}, {}}, ref{"reference", "#c0392b", {}, {}};
    const auto& dm = c.trace;
    const auto& dr = a.circle_reference->trace;
    for (std::size_t i : thin(dm.angle_deg.size(), 2500)) {
      const double x = static_cast<double>(i) / static_cast<double>(dm.angle_deg.size()) * c.revolutions * 360.0;
      meas.x.push_back(x), meas.y.push_back(dm.radius_deviation_um[i]);
      if (i < dr.radius_deviation_um.size()) ref.x.push_back(x), ref.y.push_back(dr.radius_deviation_um[i]);
    }
    r.svgs.push_back(line_plot({meas, ref}, "Radius deviation along the path", "path angle (deg, all revolutions)", "µm"));
    page.sections.push_back(std::move(r));
  }
}

void step_sections(const dsp::Analysis& a, Page& page, const fs::path& dir) {
  const auto& st = *a.step;
  Section s;
  s.heading = "Step response (axis " + a.step_axis + ")";
  s.figures = {{"End-position error (mean)", st.end_position_error_um, "µm", 2, ""},
               {"Scatter over repeats", st.scatter_um, "µm", 2, "pooled std, same target and direction"},
               {"Overshoot (max)", st.overshoot_um, "µm", 2, ""},
               {"Settling time (max)", st.settling_s * 1000.0, "ms", 1, "into ±1 µm"},
               {"Noise in the dwell", st.noise_um, "µm", 3, ""},
               {"Smallest step resolved", st.smallest_step_resolved_um > 0 ? std::optional<double>(st.smallest_step_resolved_um) : std::nullopt,
                "µm", 1, ""}};
  const auto& m = a.measurement;
  const int ax = a.step_axis == "y" ? 1 : a.step_axis == "z" ? 2 : 0;
  LineSeries err{"measured − set-point", "#1f5fbf", {}, {}};
  std::vector<double> t, pos, cmd, e;
  for (std::size_t i = 0; i < m.sample_index.size(); ++i) {
    t.push_back(static_cast<double>(m.sample_index[i]) / m.fs_hz);
    pos.push_back(m.pos_mm[i][ax]);
    cmd.push_back(m.cmd_mm[i][ax]);
    e.push_back((m.pos_mm[i][ax] - m.cmd_mm[i][ax]) * 1000.0);
  }
  for (std::size_t i : thin(t.size(), 3000)) err.x.push_back(t[i]), err.y.push_back(e[i]);
  s.svgs.push_back(line_plot({err}, "Following error", "time (s)", "µm"));
  page.sections.push_back(std::move(s));
  write_csv(dir / "trace_step.csv", "t_s,position_mm,setpoint_mm,error_um", {t, pos, cmd, e});
}

}  // namespace

fs::path write_run_report(const dsp::Run& run, const dsp::Analysis& a, const fs::path& dir) {
  fs::create_directories(dir);
  Page page;
  page.title = "eical — " + run.meta.program.kind + " test, run " + run.meta.id;
  page.subtitle = "machine " + run.meta.machine.name + " · " + fmt("%.0f Hz", run.meta.acquisition.fs_hz) + " · " +
                  std::to_string(run.frames.size()) + " samples" + (run.meta.created.empty() ? "" : " · " + run.meta.created);
  page.warnings = a.flags;
  if (a.degraded && page.warnings.empty()) page.warnings.push_back("result degraded");
  if (a.circle) circle_sections(run, a, page, dir);
  if (a.step) step_sections(a, page, dir);
  const auto& m = a.measurement;
  Section p;
  p.heading = "Measurement";
  p.figures = {{"Rest window before the motion", static_cast<double>(m.rest_window_samples) / m.fs_hz, "s", 3, "bias reference (M101 → first motion)"},
               {"ZUPT window after the motion", static_cast<double>(m.zupt_window_samples) / m.fs_hz, "s", 3, ""},
               {"Velocity error removed by ZUPT (x)", m.zupt_velocity_error_mm_s.x() * 1000.0, "µm/s", 2, ""},
               {"Velocity error removed by ZUPT (y)", m.zupt_velocity_error_mm_s.y() * 1000.0, "µm/s", 2, ""},
               {"Relative rest acceleration z", m.rest_bias_rel_mps2.z(), "m/s²", 5, "head − table incl. gravity and bias"}};
  p.notes.push_back("Pipeline: data-sheet static compensation, rest-window bias, trapezoid double integration, "
                    "two-stage dynamic compensation (6-38) including the DAQ group delay, ZUPT after the motion.");
  page.sections.push_back(std::move(p));
  const fs::path file = dir / "report.html";
  write_html(page, file);
  return file;
}

}  // namespace eical::tools::report
