#pragma once
// Self-contained SVG plots for the HTML reports (no external scripts or fonts).
#include <string>
#include <vector>

namespace eical::tools::report {

// One trace of a polar radius-deviation plot, e.g. one direction of a circular test.
struct PolarTrace {
  std::string label;
  std::string color;  // CSS colour
  std::vector<double> angle_deg;
  std::vector<double> deviation_um;
};

// Ballbar-style polar plot: the deviation is drawn magnified about a reference circle
// so that micrometres are visible on a radius of millimetres. `scale_um_per_div` is
// chosen automatically when <= 0.
std::string polar_plot(const std::vector<PolarTrace>& traces, const std::string& title,
                       double scale_um_per_div = 0.0);

struct LineSeries {
  std::string label;
  std::string color;
  std::vector<double> x;
  std::vector<double> y;
};

// x/y line plot with axes, ticks and a legend.
std::string line_plot(const std::vector<LineSeries>& series, const std::string& title,
                      const std::string& x_label, const std::string& y_label);

// Escape text for XML/HTML.
std::string xml_escape(const std::string& text);

// A "nice" tick step (1, 2, 5 × 10^k) so that `span` holds about `target_ticks` steps.
double nice_step(double span, int target_ticks);

}  // namespace eical::tools::report
