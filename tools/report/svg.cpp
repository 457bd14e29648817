#include "tools/report/svg.hpp"

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
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
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

std::string polar_plot(const std::vector<PolarTrace>& traces, const std::string& title,
                       double scale_um_per_div) {
  // Geometry: the reference circle (zero deviation) at r0; each division is `ring` px.
  const double size = 420.0, c = size / 2.0, r0 = 120.0, ring = 30.0;
  const int divisions = 2;  // rings inside and outside the reference circle
  double max_abs_um = 0.0;
  for (const auto& t : traces)
    for (double d : t.deviation_um)
      if (std::isfinite(d)) max_abs_um = std::max(max_abs_um, std::abs(d));
  if (scale_um_per_div <= 0.0) scale_um_per_div = nice_step(std::max(max_abs_um, 0.1), divisions) ;
  if (scale_um_per_div * divisions < max_abs_um)
    scale_um_per_div = nice_step(max_abs_um * 1.01, divisions - 1);
  const double px_per_um = ring / scale_um_per_div;

  std::string s;
  s += "<svg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 " + num(size) + " " + num(size + 40) +
       "' width='" + num(size) + "' height='" + num(size + 40) + "' font-family='sans-serif' font-size='11'>";
  s += "<text x='" + num(c) + "' y='16' text-anchor='middle' font-size='14' font-weight='bold'>" +
       xml_escape(title) + "</text>";
  s += "<g transform='translate(0,24)'>";
  for (int k = -divisions; k <= divisions; ++k) {
    const double r = r0 + k * ring;
    s += "<circle cx='" + num(c) + "' cy='" + num(c) + "' r='" + num(r) + "' fill='none' stroke='" +
         (k == 0 ? "#444" : "#ccc") + "' stroke-width='" + (k == 0 ? "1.2" : "0.8") +
         (k == 0 ? "'" : "' stroke-dasharray='3,3'") + "/>";
    s += "<text x='" + num(c + 3) + "' y='" + num(c - r - 2) + "' fill='#777'>" +
         tick_label(k * scale_um_per_div, scale_um_per_div) + " µm</text>";
  }
  for (int a = 0; a < 360; a += 30) {
    const double th = a * kPi / 180.0;
    const double r1 = r0 - divisions * ring, r2 = r0 + divisions * ring + 6;
    s += "<line x1='" + num(c + r1 * std::cos(th)) + "' y1='" + num(c - r1 * std::sin(th)) + "' x2='" +
         num(c + r2 * std::cos(th)) + "' y2='" + num(c - r2 * std::sin(th)) + "' stroke='#e4e4e4'/>";
    s += "<text x='" + num(c + (r2 + 10) * std::cos(th)) + "' y='" + num(c - (r2 + 10) * std::sin(th) + 4) +
         "' text-anchor='middle' fill='#555'>" + std::to_string(a) + "°</text>";
  }
  double legend_y = size - 8;
  for (const auto& t : traces) {
    std::string pts;
    const std::size_t n = std::min(t.angle_deg.size(), t.deviation_um.size());
    // Thin out very long traces; the plot resolution is well below 2000 points.
    const std::size_t stride = std::max<std::size_t>(1, n / 2000);
    for (std::size_t i = 0; i < n; i += stride) {
      if (!std::isfinite(t.deviation_um[i]) || !std::isfinite(t.angle_deg[i])) continue;
      const double th = t.angle_deg[i] * kPi / 180.0;
      const double r = std::max(0.0, r0 + t.deviation_um[i] * px_per_um);
      pts += num(c + r * std::cos(th)) + "," + num(c - r * std::sin(th)) + " ";
    }
    s += "<polyline fill='none' stroke='" + t.color + "' stroke-width='1.3' points='" + pts + "'/>";
    s += "<rect x='8' y='" + num(legend_y - 9) + "' width='12' height='3' fill='" + t.color + "'/>";
    s += "<text x='24' y='" + num(legend_y - 5) + "'>" + xml_escape(t.label) + "</text>";
    legend_y -= 14;
  }
  s += "<text x='" + num(size - 8) + "' y='" + num(size - 8) + "' text-anchor='end' fill='#555'>" +
       tick_label(scale_um_per_div, scale_um_per_div) + " µm / division</text>";
  s += "</g></svg>";
  return s;
}

std::string line_plot(const std::vector<LineSeries>& series, const std::string& title,
                      const std::string& x_label, const std::string& y_label) {
  const double w = 640, h = 300, left = 60, right = 16, top = 28, bottom = 42;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const auto& s : series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]), ymax = std::max(ymax, s.y[i]);
    }
  }
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  if (xmax <= xmin) xmax = xmin + 1;
  if (ymax <= ymin) ymin -= 0.5, ymax += 0.5;
  const double ypad = 0.05 * (ymax - ymin);
  ymin -= ypad, ymax += ypad;
  const auto X = [&](double x) { return left + (x - xmin) / (xmax - xmin) * (w - left - right); };
  const auto Y = [&](double y) { return top + (ymax - y) / (ymax - ymin) * (h - top - bottom); };

  std::string s = "<svg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 640 300' width='640' height='300' "
                  "font-family='sans-serif' font-size='11'>";
  s += "<text x='" + num(w / 2) + "' y='16' text-anchor='middle' font-size='13' font-weight='bold'>" +
       xml_escape(title) + "</text>";
  s += "<rect x='" + num(left) + "' y='" + num(top) + "' width='" + num(w - left - right) + "' height='" +
       num(h - top - bottom) + "' fill='none' stroke='#888'/>";
  const double xs = nice_step(xmax - xmin, 8), ys = nice_step(ymax - ymin, 6);
  for (double x = std::ceil(xmin / xs) * xs; x <= xmax + 1e-12; x += xs) {
    s += "<line x1='" + num(X(x)) + "' y1='" + num(top) + "' x2='" + num(X(x)) + "' y2='" + num(h - bottom) +
         "' stroke='#eee'/><text x='" + num(X(x)) + "' y='" + num(h - bottom + 14) + "' text-anchor='middle'>" +
         tick_label(x, xs) + "</text>";
  }
  for (double y = std::ceil(ymin / ys) * ys; y <= ymax + 1e-12; y += ys) {
    s += "<line x1='" + num(left) + "' y1='" + num(Y(y)) + "' x2='" + num(w - right) + "' y2='" + num(Y(y)) +
         "' stroke='#eee'/><text x='" + num(left - 4) + "' y='" + num(Y(y) + 4) + "' text-anchor='end'>" +
         tick_label(y, ys) + "</text>";
  }
  s += "<text x='" + num((left + w - right) / 2) + "' y='" + num(h - 6) + "' text-anchor='middle'>" +
       xml_escape(x_label) + "</text>";
  s += "<text transform='translate(14," + num((top + h - bottom) / 2) + ") rotate(-90)' text-anchor='middle'>" +
       xml_escape(y_label) + "</text>";
  double ly = top + 12;
  for (const auto& ser : series) {
    std::string pts;
    const std::size_t n = std::min(ser.x.size(), ser.y.size());
    const std::size_t stride = std::max<std::size_t>(1, n / 3000);
    for (std::size_t i = 0; i < n; i += stride)
      if (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i])) pts += num(X(ser.x[i])) + "," + num(Y(ser.y[i])) + " ";
    s += "<polyline fill='none' stroke='" + ser.color + "' stroke-width='1.2' points='" + pts + "'/>";
    s += "<rect x='" + num(w - right - 150) + "' y='" + num(ly - 6) + "' width='12' height='3' fill='" + ser.color +
         "'/><text x='" + num(w - right - 134) + "' y='" + num(ly - 2) + "'>" + xml_escape(ser.label) + "</text>";
    ly += 14;
  }
  s += "</svg>";
  return s;
}

}  // namespace eical::tools::report
