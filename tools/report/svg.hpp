#pragma once
// Self-contained SVG plots for the HTML reports (no scripts, no external fonts). Every
// plot states its units on its axes; text uses the page's font (inherit).
#include <string>
#include <vector>

namespace eical::tools::report {

// Colours shared by all plots so that a direction keeps its colour across a report.
inline constexpr const char* kBlue = "#1f5fbf";  // ccw, ↑ (positive approach), measured
inline constexpr const char* kRed = "#c0392b";   // cw, ↓ (negative approach)
inline constexpr const char* kGrey = "#7b8494";  // set-point, reference
inline constexpr const char* kGreen = "#1e8449";

// One trace of a polar radius-deviation plot, e.g. one revolution of one direction.
struct PolarTrace {
  std::string label;  // empty: not in the legend
  std::string color;  // CSS colour
  std::vector<double> angle_deg;
  std::vector<double> deviation_um;
  bool start_marker = false;  // a marker where the trace begins
};
// What the polar plot draws instead of a shape the measurement cannot resolve: a shaded
// ring ±half_width_um about the reference circle, with its label in the legend.
struct PolarBand {
  double half_width_um = 0.0;  // <= 0: no band
  std::string color;
  std::string label;
};

// Colours of the revolutions of one direction: ccw blues, cw reds (first = kBlue / kRed).
const char* revolution_colour(bool ccw, int revolution);

// Ballbar-style polar plot: the deviation is drawn magnified about a reference circle
// (zero deviation) with rings every `scale_um_per_div` (chosen when <= 0). `axis_a` and
// `axis_b` name the plane's axes at 0° and 90° (e.g. "+X", "+Y"). Labels are drawn above
// the traces (with a white halo) so that no trace hides them; `subtitle` (e.g. G per
// direction) is printed under the title. The trace is drawn as measured: a revolution is
// not joined back to its start (the join would draw the integration's closure as shape).
std::string polar_plot(const std::vector<PolarTrace>& traces, const std::string& title,
                       const std::string& axis_a = "0°", const std::string& axis_b = "90°",
                       double scale_um_per_div = 0.0, const std::string& subtitle = "", const PolarBand& band = {});

struct LineSeries {
  std::string label = {};
  std::string color = {};
  std::vector<double> x = {};
  std::vector<double> y = {};
  std::vector<double> y_lo = {}, y_hi = {};  // optional band (same length as x), drawn shaded
  bool markers = false;                      // points instead of a line
  bool dashed = false;
  double width = 1.4;
  bool error_bars = false;  // y_lo..y_hi as a bar at each point (separate measurements) instead of a band
};

// x/y plot with axes, ticks, grid and a legend under the frame (never over the data);
// labels carry the units, e.g. "time (s)". height_px is the frame's; the legend adds its rows.
std::string line_plot(const std::vector<LineSeries>& series, const std::string& title, const std::string& x_label,
                      const std::string& y_label, double width_px = 680, double height_px = 300);

// Plane view of a path with its deviation magnified: the set-point path in grey and
// set-point + magnification · (measured − set-point) in colour, equal axis scales.
// Arrows (optional) show corner errors at the same magnification.
struct PathView {
  std::vector<double> cmd_a_mm, cmd_b_mm;    // set-point, plane axes
  std::vector<double> base_a_mm, base_b_mm;  // where the deviations apply (points of the set-point path)
  std::vector<double> dev_a_um, dev_b_um;    // deviation at those points (e.g. the contour-normal part)
  std::vector<double> arrow_a_mm, arrow_b_mm, arrow_da_um, arrow_db_um;  // e.g. corner errors
};
std::string path_plot(const PathView& view, const std::string& title, const std::string& axis_a,
                      const std::string& axis_b);

// Escape text for XML/HTML.
std::string xml_escape(const std::string& text);

// A "nice" tick step (1, 2, 5 × 10^k) so that `span` holds about `target_ticks` steps.
double nice_step(double span, int target_ticks);

}  // namespace eical::tools::report
