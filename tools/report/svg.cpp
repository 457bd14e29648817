#include "tools/report/svg.hpp"
#include "dsp/core/float_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace eical::tools::report {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  if (std::abs(v) < step * 1e-6) v = 0.0;  // no "-0"
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string svg_open(double w, double h, const char* css_class = "plot") {
  return "<svg xmlns='http://www.w3.org/2000/svg' class='" + std::string(css_class) + "' viewBox='0 0 " + num(w) + " " +
         num(h) + "' width='" + num(w) + "' height='" + num(h) +
         "' font-family='inherit' font-size='11' fill='#1d2330'>";
}

std::string text(double x, double y, const std::string& s, const std::string& extra = "") {
  return "<text x='" + num(x) + "' y='" + num(y) + "'" + (extra.empty() ? "" : " " + extra) + ">" + xml_escape(s) +
         "</text>";
}

// Every `stride`-th point so that a trace has at most `max_points` (plots need no more).
std::size_t stride_for(std::size_t n, std::size_t max_points) { return std::max<std::size_t>(1, n / max_points); }

// The next step of the 1-2-5 sequence above `step`.
double next_nice(double step) {
  const double mag = std::pow(10.0, std::floor(std::log10(step)));
  const double norm = step / mag;
  return (norm < 1.5 ? 2.0 : norm < 3.5 ? 5.0 : 10.0) * mag;
}

// Tick positions k·step inside [lo, hi], counted (not accumulated) so that rounding can
// neither skip the last tick nor loop forever.
std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> t;
  if (!(step > 0.0) || !std::isfinite(lo) || !std::isfinite(hi)) return t;
  const double k0 = std::ceil(lo / step - 1e-9), k1 = std::floor(hi / step + 1e-9);
  for (double k = k0; k <= k1 && t.size() < 200; k += 1.0) t.push_back(k * step);
  return t;
}

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

double nice_step(double span, int target_ticks) {
  if (!(span > 0.0) || !std::isfinite(span)) return 1.0;
  const double raw = span / std::max(1, target_ticks);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double nice = norm < 1.5 ? 1.0 : norm < 3.5 ? 2.0 : norm < 7.5 ? 5.0 : 10.0;
  return nice * mag;
}

const char* revolution_colour(bool ccw, int revolution) {
  static const char* const blues[] = {kBlue,     "#0e8fa3", "#6a3fb5", "#2c4f8a",
                                      "#3aa35d", "#7d93d9", "#0b5563", "#9b59b6"};
  static const char* const reds[] = {kRed, "#e67e22", "#a93270", "#8a4b08", "#d4a017", "#e0766a", "#6e2c00", "#c2185b"};
  const int n = 8;
  const int i = ((revolution % n) + n) % n;
  return ccw ? blues[i] : reds[i];
}

namespace {

// The ballbar plot's fixed geometry: the reference circle (zero deviation) at r0 with
// `divisions` rings inside and outside, each `ring` px, at a µm-per-division scale; spokes
// from r1 to r2; the legend's rows under it.
struct PolarGeometry {
  double w = 500, cy = 276, r0 = 122.0, ring = 28.0, c = w / 2.0;
  double h = 0.0;
  int divisions = 3;
  double scale_um_per_div = 0.0, px_per_um = 0.0;
  double r1 = 0.0, r2 = 0.0;

  void point(double ang_deg, double dev_um, double& x, double& y) const {
    const double th = ang_deg * kPi / 180.0;
    const double r = std::max(0.0, r0 + dev_um * px_per_um);
    x = c + r * std::cos(th), y = cy - r * std::sin(th);
  }
};

// The scale: the one asked for, else a nice step for the largest deviation, raised until
// every deviation fits inside the outer ring.
PolarGeometry polar_geometry(const std::vector<PolarTrace>& traces, double scale_um_per_div, const PolarBand& band) {
  PolarGeometry g;
  std::size_t labelled = band.half_width_um > 0.0 ? 1 : 0;
  for (const auto& t : traces) labelled += t.label.empty() ? 0 : 1;
  const double legend_rows = static_cast<double>((labelled + 1) / 2);
  g.h = g.cy + 3 * g.ring + g.r0 + 34 + 15 * legend_rows + 34;
  double max_abs_um = 0.0;
  for (const auto& t : traces)
    for (double d : t.deviation_um)
      if (std::isfinite(d)) max_abs_um = std::max(max_abs_um, std::abs(d));
  if (std::isfinite(band.half_width_um)) max_abs_um = std::max(max_abs_um, band.half_width_um);
  if (scale_um_per_div <= 0.0) scale_um_per_div = nice_step(std::max(max_abs_um, 0.05) * 1.05, g.divisions);
  while (scale_um_per_div * g.divisions < max_abs_um) scale_um_per_div = next_nice(scale_um_per_div);
  g.scale_um_per_div = scale_um_per_div;
  g.px_per_um = g.ring / scale_um_per_div;
  g.r1 = g.r0 - g.divisions * g.ring, g.r2 = g.r0 + g.divisions * g.ring + 4;
  return g;
}

// Rings and spokes, drawn first (under the traces).
std::string polar_grid(const PolarGeometry& g) {
  const double c = g.c, cy = g.cy, r1 = g.r1, r2 = g.r2;
  std::string s;
  for (int k = -g.divisions; k <= g.divisions; ++k) {
    const double r = g.r0 + k * g.ring;
    s += "<circle cx='" + num(c) + "' cy='" + num(cy) + "' r='" + num(r) + "' fill='none' stroke='" +
         (k == 0 ? "#8a93a3" : "#d5d9e0") + "' stroke-width='" + (k == 0 ? "1.1" : "0.8") +
         (k == 0 ? "'" : "' stroke-dasharray='3,3'") + "/>";
  }
  for (int a = 0; a < 360; a += 30) {
    const double th = a * kPi / 180.0;
    s += "<line x1='" + num(c + r1 * std::cos(th)) + "' y1='" + num(cy - r1 * std::sin(th)) + "' x2='" +
         num(c + r2 * std::cos(th)) + "' y2='" + num(cy - r2 * std::sin(th)) + "' stroke='#e6e9ee'/>";
  }
  return s;
}

// The band: an annulus between −w and +w about the reference circle (even-odd fill).
std::string polar_band(const PolarBand& band, const PolarGeometry& g) {
  if (!(band.half_width_um > 0.0)) return {};
  const double ro = g.r0 + band.half_width_um * g.px_per_um,
               ri = std::max(0.0, g.r0 - band.half_width_um * g.px_per_um);
  auto circle = [&](double r) {
    return "M" + num(g.c + r) + "," + num(g.cy) + " a" + num(r) + "," + num(r) + " 0 1,0 " + num(-2 * r) + ",0 a" +
           num(r) + "," + num(r) + " 0 1,0 " + num(2 * r) + ",0 ";
  };
  return "<path fill-rule='evenodd' d='" + circle(ro) + circle(ri) + "' fill='" + band.color +
         "' fill-opacity='0.16' stroke='" + band.color + "' stroke-opacity='0.5' stroke-width='0.8'/>";
}

// Traces: one polyline per revolution as measured, a marker at its start (the markers after
// every trace, so that none hides under the next).
std::string polar_traces(const std::vector<PolarTrace>& traces, const PolarGeometry& g) {
  std::string s, markers;
  for (const auto& t : traces) {
    const std::size_t n = std::min(t.angle_deg.size(), t.deviation_um.size());
    if (n == 0) continue;
    const std::size_t stride = stride_for(n, 1500);
    std::string pts;
    double prev_ang = kNaN, x = 0, y = 0;
    for (std::size_t i = 0; i < n; i += stride) {
      if (!std::isfinite(t.deviation_um[i]) || !std::isfinite(t.angle_deg[i])) continue;
      // A jump in angle (a gap in the data) starts a new polyline.
      if (std::isfinite(prev_ang) && std::abs(t.angle_deg[i] - prev_ang) > 5.0 &&
          std::abs(std::abs(t.angle_deg[i] - prev_ang) - 360.0) > 5.0) {
        s += "<polyline fill='none' stroke='" + t.color + "' stroke-width='1.3' stroke-linejoin='round' points='" +
             pts + "'/>";
        pts.clear();
      }
      prev_ang = t.angle_deg[i];
      g.point(t.angle_deg[i], t.deviation_um[i], x, y);
      pts += num(x) + "," + num(y) + " ";
    }
    s += "<polyline fill='none' stroke='" + t.color + "' stroke-width='1.3' stroke-linejoin='round' points='" + pts +
         "'/>";
    if (t.start_marker) {
      g.point(t.angle_deg[0], t.deviation_um[0], x, y);
      markers += "<circle cx='" + num(x) + "' cy='" + num(y) + "' r='3.6' fill='#ffffff' stroke='" + t.color +
                 "' stroke-width='1.8'/>";
    }
  }
  return s + markers;
}

// The rings' µm and the angles (the plane's axes at 0° and 90°), above the traces on a
// white halo.
std::string polar_labels(const PolarGeometry& g, const std::string& axis_a, const std::string& axis_b) {
  const std::string halo = " stroke='#ffffff' stroke-width='3' paint-order='stroke' stroke-linejoin='round'";
  const double c = g.c, cy = g.cy, r2 = g.r2;
  std::string s;
  for (int k = -g.divisions; k <= g.divisions; ++k)
    if (k != 0) {
      const double r = g.r0 + k * g.ring;
      s += text(c + 3, cy - r - 2, (k > 0 ? "+" : "") + tick_label(k * g.scale_um_per_div, g.scale_um_per_div),
                "fill='#6b7385' font-size='9'" + halo);
    }
  for (int a = 0; a < 360; a += 30) {
    const double th = a * kPi / 180.0;
    std::string lab = std::to_string(a) + "°";
    if (a == 0) lab = axis_a;
    if (a == 90) lab = axis_b;
    s += text(c + (r2 + 14) * std::cos(th), cy - (r2 + 14) * std::sin(th) + 4, lab,
              "text-anchor='middle' fill='#4a5366'" + std::string(a % 90 == 0 ? " font-weight='600'" : "") + halo);
  }
  return s;
}

// Legend in two columns under the plot, the scale beside.
std::string polar_legend(const std::vector<PolarTrace>& traces, const PolarBand& band, const PolarGeometry& g) {
  const double w = g.w, h = g.h;
  std::string s;
  double ly = g.cy + g.r2 + 34;
  std::size_t k = 0;
  auto entry = [&](const std::string& label, const std::string& color, double bar_h) {
    const double lx = k % 2 == 0 ? 10.0 : 250.0;
    s += "<rect x='" + num(lx) + "' y='" + num(ly - 3 - bar_h / 2) + "' width='16' height='" + num(bar_h) + "' fill='" +
         color + "'" + (bar_h > 3 ? " fill-opacity='0.3'" : "") + "/>";
    s += text(lx + 22, ly, label);
    if (k % 2 == 1) ly += 15;
    ++k;
  };
  if (band.half_width_um > 0.0) entry(band.label, band.color, 9);
  for (const auto& t : traces)
    if (!t.label.empty()) entry(t.label, t.color, 3);
  s += "<circle cx='" + num(14) + "' cy='" + num(h - 9) +
       "' r='3.6' fill='#ffffff' stroke='#4a5366' stroke-width='1.8'/>" +
       text(24, h - 5, "start of a revolution (drawn as measured, not joined)", "fill='#4a5366' font-size='10'");
  s += text(w - 10, h - 21, tick_label(g.scale_um_per_div, g.scale_um_per_div) + " µm / division",
            "text-anchor='end' fill='#4a5366'");
  s += text(w - 10, h - 5, "reference circle = 0 µm", "text-anchor='end' fill='#6b7385' font-size='10'");
  return s;
}

// A line plot's frame: its margins, the data's ranges (padded) and their mapping to px.
struct PlotFrame {
  double w = 0.0, h = 0.0;
  double left = 64, right = 18, top = 30, bottom = 44;
  double xmin = 0.0, xmax = 0.0, ymin = 0.0, ymax = 0.0;
  [[nodiscard]] double x_px(double x) const { return left + (x - xmin) / (xmax - xmin) * (w - left - right); }
  [[nodiscard]] double y_px(double y) const { return top + (ymax - y) / (ymax - ymin) * (h - top - bottom); }
};

// The ranges of every finite point and band; a degenerate range widened, y padded by 6 %.
PlotFrame plot_frame(const std::vector<LineSeries>& series, double w, double h) {
  PlotFrame f;
  f.w = w, f.h = h;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  auto extend_y = [&](double y) {
    if (std::isfinite(y)) ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  };
  for (const auto& s : series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]);
      extend_y(s.y[i]);
      if (i < s.y_lo.size()) extend_y(s.y_lo[i]);
      if (i < s.y_hi.size()) extend_y(s.y_hi[i]);
    }
  }
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  if (xmax <= xmin) xmin -= 0.5, xmax += 0.5;
  if (ymax <= ymin) ymin -= 0.5, ymax += 0.5;
  const double ypad = 0.06 * (ymax - ymin);
  ymin -= ypad, ymax += ypad;
  // Points and bars at the ends of x would sit on the frame, half hidden: pad x for them.
  if (std::any_of(series.begin(), series.end(), [](const LineSeries& s) { return s.markers || s.error_bars; })) {
    const double xpad = 0.02 * (xmax - xmin);
    xmin -= xpad, xmax += xpad;
  }
  f.xmin = xmin, f.xmax = xmax, f.ymin = ymin, f.ymax = ymax;
  return f;
}

// Title, grid with tick labels, the frame and the axis labels.
std::string plot_axes(const PlotFrame& f, const std::string& title, const std::string& x_label,
                      const std::string& y_label) {
  const double w = f.w, h = f.h, left = f.left, right = f.right, top = f.top, bottom = f.bottom;
  std::string s = text(w / 2, 17, title, "text-anchor='middle' font-size='13' font-weight='600'");
  const double xs = nice_step(f.xmax - f.xmin, 8), ys = nice_step(f.ymax - f.ymin, 6);
  for (double x : ticks(f.xmin, f.xmax, xs))
    s += "<line x1='" + num(f.x_px(x)) + "' y1='" + num(top) + "' x2='" + num(f.x_px(x)) + "' y2='" + num(h - bottom) +
         "' stroke='#edf0f4'/>" +
         text(f.x_px(x), h - bottom + 15, tick_label(x, xs), "text-anchor='middle' fill='#4a5366'");
  for (double y : ticks(f.ymin, f.ymax, ys))
    s += "<line x1='" + num(left) + "' y1='" + num(f.y_px(y)) + "' x2='" + num(w - right) + "' y2='" + num(f.y_px(y)) +
         "' stroke='" + (std::abs(y) < ys * 1e-6 ? "#9aa3b2" : "#edf0f4") + "'/>" +
         text(left - 5, f.y_px(y) + 4, tick_label(y, ys), "text-anchor='end' fill='#4a5366'");
  s += "<rect x='" + num(left) + "' y='" + num(top) + "' width='" + num(w - left - right) + "' height='" +
       num(h - top - bottom) + "' fill='none' stroke='#8a93a3'/>";
  s += text((left + w - right) / 2, h - 8, x_label, "text-anchor='middle'");
  s += "<text transform='translate(15," + num((top + h - bottom) / 2) + ") rotate(-90)' text-anchor='middle'>" +
       xml_escape(y_label) + "</text>";
  return s;
}

// Bands (or error bars), drawn before the lines so that the lines stay on top.
std::string plot_bands(const std::vector<LineSeries>& series, const PlotFrame& f) {
  std::string s;
  for (const auto& ser : series) {
    const std::size_t n = std::min({ser.x.size(), ser.y_lo.size(), ser.y_hi.size()});
    if (ser.error_bars) {
      for (std::size_t i = 0; i < n; ++i)
        if (std::isfinite(ser.x[i]) && std::isfinite(ser.y_lo[i]) && std::isfinite(ser.y_hi[i]))
          s += "<line x1='" + num(f.x_px(ser.x[i])) + "' y1='" + num(f.y_px(ser.y_lo[i])) + "' x2='" +
               num(f.x_px(ser.x[i])) + "' y2='" + num(f.y_px(ser.y_hi[i])) + "' stroke='" + ser.color +
               "' stroke-opacity='0.6' stroke-width='1.2'/>";
      continue;
    }
    if (n < 2) continue;
    std::string pts;
    for (std::size_t i = 0; i < n; ++i) pts += num(f.x_px(ser.x[i])) + "," + num(f.y_px(ser.y_hi[i])) + " ";
    for (std::size_t i = n; i-- > 0;) pts += num(f.x_px(ser.x[i])) + "," + num(f.y_px(ser.y_lo[i])) + " ";
    s += "<polygon points='" + pts + "' fill='" + ser.color + "' fill-opacity='0.13' stroke='" + ser.color +
         "' stroke-opacity='0.35' stroke-width='0.7'/>";
  }
  return s;
}

// Rows of the legend under the frame: three entries to a row.
constexpr std::size_t kLegendColumns = 3;
constexpr double kLegendRowPx = 15.0;
std::size_t legend_rows(const std::vector<LineSeries>& series) {
  const auto labelled = static_cast<std::size_t>(
      std::count_if(series.begin(), series.end(), [](const LineSeries& s) { return !s.label.empty(); }));
  return (labelled + kLegendColumns - 1) / kLegendColumns;
}

// The series as lines or markers, then the legend under the frame's axis label, where no
// trace can pass.
std::string plot_lines_and_legend(const std::vector<LineSeries>& series, const PlotFrame& f) {
  const double column_px = (f.w - f.left - f.right) / static_cast<double>(kLegendColumns);
  std::string s;
  std::string legend;
  std::size_t k = 0;
  for (const auto& ser : series) {
    const std::size_t n = std::min(ser.x.size(), ser.y.size());
    const std::size_t stride = stride_for(n, 3000);
    if (ser.markers) {
      for (std::size_t i = 0; i < n; i += stride)
        if (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i]))
          s += "<circle cx='" + num(f.x_px(ser.x[i])) + "' cy='" + num(f.y_px(ser.y[i])) + "' r='2.2' fill='" +
               ser.color + "' fill-opacity='0.7'/>";
    } else {
      std::string pts;
      for (std::size_t i = 0; i < n; i += stride)
        if (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i]))
          pts += num(f.x_px(ser.x[i])) + "," + num(f.y_px(ser.y[i])) + " ";
      s += "<polyline fill='none' stroke='" + ser.color + "' stroke-width='" + num(ser.width) +
           "' stroke-linejoin='round'" + (ser.dashed ? " stroke-dasharray='5,3'" : "") + " points='" + pts + "'/>";
    }
    if (ser.label.empty()) continue;
    const double lx = f.left + static_cast<double>(k % kLegendColumns) * column_px,
                 ly = f.h + 12.0 + static_cast<double>(k / kLegendColumns) * kLegendRowPx;
    legend += ser.markers
                  ? "<circle cx='" + num(lx + 8) + "' cy='" + num(ly - 4) + "' r='2.5' fill='" + ser.color + "'/>"
                  : "<rect x='" + num(lx) + "' y='" + num(ly - 5) + "' width='16' height='3' fill='" + ser.color + "'" +
                        (ser.dashed ? " fill-opacity='0.6'" : "") + "/>";
    legend += text(lx + 22, ly, ser.label, "fill='#1d2330'");
    ++k;
  }
  return s + legend;
}

}  // namespace

std::string polar_plot(const std::vector<PolarTrace>& traces, const std::string& title, const std::string& axis_a,
                       const std::string& axis_b, double scale_um_per_div, const std::string& subtitle,
                       const PolarBand& band) {
  const PolarGeometry g = polar_geometry(traces, scale_um_per_div, band);
  std::string s = svg_open(g.w, g.h, "plot polar");
  s += text(g.c, 18, title, "text-anchor='middle' font-size='14' font-weight='600'");
  if (!subtitle.empty()) s += text(g.c, 34, subtitle, "text-anchor='middle' font-size='11' fill='#4a5366'");
  s += polar_grid(g);
  s += polar_band(band, g);
  s += polar_traces(traces, g);
  s += polar_labels(g, axis_a, axis_b);
  s += polar_legend(traces, band, g);
  return s + "</svg>";
}

std::string line_plot(const std::vector<LineSeries>& series, const std::string& title, const std::string& x_label,
                      const std::string& y_label, double width_px, double height_px) {
  const PlotFrame f = plot_frame(series, width_px, height_px);
  const double legend_px = static_cast<double>(legend_rows(series)) * kLegendRowPx;
  std::string s = svg_open(width_px, height_px + (legend_px > 0 ? legend_px + 4 : 0));
  s += plot_axes(f, title, x_label, y_label);
  s += plot_bands(series, f);
  s += plot_lines_and_legend(series, f);
  return s + "</svg>";
}

std::string path_plot(const PathView& view, const std::string& title, const std::string& axis_a,
                      const std::string& axis_b) {
  const double w = 460, pad = 46, top = 28, max_plot_h = 400;
  double amin = kInf, amax = -kInf, bmin = kInf, bmax = -kInf, dmax_um = 0.0;
  for (std::size_t i = 0; i < view.cmd_a_mm.size(); ++i) {
    amin = std::min(amin, view.cmd_a_mm[i]), amax = std::max(amax, view.cmd_a_mm[i]);
    bmin = std::min(bmin, view.cmd_b_mm[i]), bmax = std::max(bmax, view.cmd_b_mm[i]);
  }
  for (std::size_t i = 0; i < view.dev_a_um.size(); ++i)
    dmax_um = std::max(dmax_um, std::hypot(view.dev_a_um[i], view.dev_b_um[i]));
  for (std::size_t i = 0; i < view.arrow_da_um.size(); ++i)
    dmax_um = std::max(dmax_um, std::hypot(view.arrow_da_um[i], view.arrow_db_um[i]));
  if (!std::isfinite(amin)) amin = bmin = 0, amax = bmax = 1;
  const double span_mm = std::max({amax - amin, bmax - bmin, 1e-3});
  // Magnify so that the largest deviation shows as about 8 % of the path's extent.
  const double mag = dmax_um > 0 ? nice_step(0.08 * span_mm * 1000.0 / dmax_um, 1) : 1.0;
  const double grow = 0.12 * span_mm;
  amin -= grow, amax += grow, bmin -= grow, bmax += grow;
  // Equal scales on both axes; the picture is as tall as the path needs.
  const double px_per_mm = std::min((w - 2 * pad) / (amax - amin), max_plot_h / (bmax - bmin));
  const double plot_h = (bmax - bmin) * px_per_mm, h = top + plot_h + pad + 22;
  const double a0 = (amin + amax) / 2, b0 = (bmin + bmax) / 2, cx = w / 2, cy = top + plot_h / 2;
  const auto X = [&](double a) { return cx + (a - a0) * px_per_mm; };
  const auto Y = [&](double b) { return cy - (b - b0) * px_per_mm; };
  std::string s = svg_open(w, h);
  s += text(w / 2, 17, title, "text-anchor='middle' font-size='13' font-weight='600'");
  const double step = nice_step(std::max(amax - amin, bmax - bmin), 6);
  for (double a : ticks(amin, amax, step))
    s += "<line x1='" + num(X(a)) + "' y1='" + num(Y(bmin)) + "' x2='" + num(X(a)) + "' y2='" + num(Y(bmax)) +
         "' stroke='#edf0f4'/>" + text(X(a), Y(bmin) + 14, tick_label(a, step), "text-anchor='middle' fill='#4a5366'");
  for (double b : ticks(bmin, bmax, step))
    s += "<line x1='" + num(X(amin)) + "' y1='" + num(Y(b)) + "' x2='" + num(X(amax)) + "' y2='" + num(Y(b)) +
         "' stroke='#edf0f4'/>" + text(X(amin) - 4, Y(b) + 4, tick_label(b, step), "text-anchor='end' fill='#4a5366'");
  s += "<rect x='" + num(X(amin)) + "' y='" + num(Y(bmax)) + "' width='" + num((amax - amin) * px_per_mm) +
       "' height='" + num((bmax - bmin) * px_per_mm) + "' fill='none' stroke='#8a93a3'/>";
  s += text(cx, Y(bmin) + 30, axis_a + " (mm)", "text-anchor='middle'");
  s += "<text transform='translate(" + num(X(amin) - 34) + "," + num(cy) + ") rotate(-90)' text-anchor='middle'>" +
       xml_escape(axis_b + " (mm)") + "</text>";
  std::string cmd, meas;
  const std::size_t n = view.cmd_a_mm.size(), stride = stride_for(n, 3000);
  for (std::size_t i = 0; i < n; i += stride) cmd += num(X(view.cmd_a_mm[i])) + "," + num(Y(view.cmd_b_mm[i])) + " ";
  const std::size_t nd = std::min(view.base_a_mm.size(), view.dev_a_um.size()), sd = stride_for(nd, 3000);
  s += "<polyline fill='none' stroke='" + std::string(kGrey) + "' stroke-width='1' stroke-dasharray='4,3' points='" +
       cmd + "'/>";
  for (std::size_t i = 0; i < nd; i += sd) {
    // A gap in the evaluated samples (a stop, a corner) starts a new polyline.
    if (i > 0 && std::hypot(view.base_a_mm[i] - view.base_a_mm[i - sd], view.base_b_mm[i] - view.base_b_mm[i - sd]) >
                     0.03 * span_mm) {
      s += "<polyline fill='none' stroke='" + std::string(kBlue) + "' stroke-width='1.3' points='" + meas + "'/>";
      meas.clear();
    }
    meas += num(X(view.base_a_mm[i] + mag * view.dev_a_um[i] * 1e-3)) + "," +
            num(Y(view.base_b_mm[i] + mag * view.dev_b_um[i] * 1e-3)) + " ";
  }
  if (!meas.empty())
    s += "<polyline fill='none' stroke='" + std::string(kBlue) + "' stroke-width='1.3' points='" + meas + "'/>";
  for (std::size_t i = 0; i < view.arrow_a_mm.size(); ++i) {
    const double x1 = X(view.arrow_a_mm[i]), y1 = Y(view.arrow_b_mm[i]);
    const double x2 = X(view.arrow_a_mm[i] + mag * view.arrow_da_um[i] * 1e-3),
                 y2 = Y(view.arrow_b_mm[i] + mag * view.arrow_db_um[i] * 1e-3);
    s += "<line x1='" + num(x1) + "' y1='" + num(y1) + "' x2='" + num(x2) + "' y2='" + num(y2) + "' stroke='" + kRed +
         "' stroke-width='2'/>";
    s += "<circle cx='" + num(x2) + "' cy='" + num(y2) + "' r='3' fill='" + kRed + "'/><circle cx='" + num(x1) +
         "' cy='" + num(y1) + "' r='2' fill='#333'/>";
  }
  char buf[96];
  std::snprintf(buf, sizeof buf, "deviation magnified ×%g (1 µm → %.3g mm)", mag, mag * 1e-3);
  s += text(w - 10, h - 6, buf, "text-anchor='end' fill='#4a5366'");
  s += "<rect x='10' y='" + num(h - 12) + "' width='16' height='3' fill='" + kBlue + "'/>" +
       text(30, h - 8, "measured (contour)", "");
  return s + "</svg>";
}

}  // namespace eical::tools::report
