#include "tools/plan/strip_layout.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace eical::tools::plan {
namespace {

struct Point {
  double x_mm = 0.0, y_mm = 0.0;
};

// The plane's two axes as the program's plane names them (a strip's `measures` is one).
std::string axis_upper(const std::string& a) {
  std::string s = a;
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The nominal path the program's head follows relative to the table, in its plane.
std::vector<Point> nominal_path(const TestProgram& p) {
  std::vector<Point> path;
  if (p.kind == dsp::ProgramKind::circle) {
    const int n = 180;
    for (int i = 0; i <= n; ++i) {
      const double a = 2.0 * std::numbers::pi * i / n;
      path.push_back({p.radius_mm * std::cos(a), p.radius_mm * std::sin(a)});
    }
  } else if (p.kind == dsp::ProgramKind::rectangle) {
    path = {{0, 0}, {p.size_mm[0], 0}, {p.size_mm[0], p.size_mm[1]}, {0, p.size_mm[1]}, {0, 0}};
  } else if (p.kind == dsp::ProgramKind::step) {
    path = {{p.from_mm, 0}, {p.to_mm, 0}};
  } else if (!p.targets_mm.empty()) {
    path = {{p.targets_mm.front(), 0}, {p.targets_mm.back(), 0}};
  }
  return path;
}

// The strip's extent along x and along y: its length lies along the axis it measures.
Point extent_mm(const dsp::PsdSpec& s) {
  return s.measures == "x" ? Point{s.length_mm, s.width_mm} : Point{s.width_mm, s.length_mm};
}

std::string orientation(const dsp::PsdSpec& s) {
  return "its length along " + axis_upper(s.measures) + " (it measures " + axis_upper(s.measures) + ")";
}

}  // namespace

std::string layout_text(const TestProgram& p) {
  if (p.psd.empty()) return "  no PSD strips: the supports are the standstills alone\n";
  std::string o =
      "  strips (on the table, under the head's light spot when the program is at the centre given; program "
      "coordinates as gen-nc writes them):\n";
  char b[300];
  for (std::size_t i = 0; i < p.psd.size(); ++i) {
    const auto& s = p.psd[i];
    std::snprintf(b, sizeof b, "    strip %zu: centre (%.3f, %.3f) mm in %s, %s, %.1f x %.1f mm\n", i + 1,
                  s.center_mm[0], s.center_mm[1], p.plane.c_str(), orientation(s).c_str(), s.length_mm, s.width_mm);
    o += b;
  }
  return o;
}

nlohmann::json layout_json(const TestProgram& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& s : p.psd)
    a.push_back({{"measures", s.measures},
                 {"center_mm", {s.center_mm[0], s.center_mm[1]}},
                 {"plane", p.plane},
                 {"length_along", s.measures},
                 {"length_mm", s.length_mm},
                 {"width_mm", s.width_mm}});
  return a;
}

std::string layout_svg(const TestProgram& p) {
  const std::vector<Point> path = nominal_path(p);
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  bool first = true;
  const auto grow = [&](double x, double y) {
    if (first) x0 = x1 = x, y0 = y1 = y, first = false;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };
  for (const auto& q : path) grow(q.x_mm, q.y_mm);
  for (const auto& s : p.psd)
    for (const double h : {-0.5, 0.5})
      grow(s.center_mm[0] + h * extent_mm(s).x_mm, s.center_mm[1] + h * extent_mm(s).y_mm);
  const double span = std::max({x1 - x0, y1 - y0, 1.0});
  const double margin = 0.15 * span, px = 600.0 / (span + 2.0 * margin);
  const auto sx = [&](double x) { return (x - x0 + margin) * px; };
  const auto sy = [&](double y) { return (y1 - y + margin) * px; };  // SVG's y points down
  // The drawing, then a legend line per strip below it (labels beside a strip would run
  // off the picture or over the path); the drawing numbers each strip.
  const double w = std::max((x1 - x0 + 2.0 * margin) * px, 420.0), h_draw = (y1 - y0 + 2.0 * margin) * px;
  const double h = h_draw + 22.0 * static_cast<double>(p.psd.size() + 1) + 12.0;
  char b[400];
  std::snprintf(b, sizeof b,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" font-family=\"sans-serif\" "
                "font-size=\"12\">\n",
                w, h);
  std::string o = b;
  o += "<polyline fill=\"none\" stroke=\"#444\" stroke-width=\"1.5\" points=\"";
  for (const auto& q : path) {
    std::snprintf(b, sizeof b, "%.1f,%.1f ", sx(q.x_mm), sy(q.y_mm));
    o += b;
  }
  o += "\"/>\n";
  for (std::size_t i = 0; i < p.psd.size(); ++i) {
    const auto& s = p.psd[i];
    // At least 3 px thick, so that a 0.5 mm strip beside a 300 mm travel is seen.
    const double wx = std::max(extent_mm(s).x_mm * px, 3.0), wy = std::max(extent_mm(s).y_mm * px, 3.0);
    // The number sits outside the path: away from the drawing's centre.
    const double cx = sx(s.center_mm[0]), cy = sy(s.center_mm[1]);
    const double dx = cx - 0.5 * w, dy = cy - 0.5 * h_draw, d = std::max(std::hypot(dx, dy), 1e-9);
    std::snprintf(b, sizeof b,
                  "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#d33\"/>\n"
                  "<text x=\"%.1f\" y=\"%.1f\" fill=\"#d33\" text-anchor=\"middle\" font-weight=\"bold\">%zu</text>\n",
                  cx - 0.5 * wx, cy - 0.5 * wy, wx, wy, cx + 16.0 * dx / d, cy + 16.0 * dy / d + 4.0, i + 1);
    o += b;
    std::snprintf(b, sizeof b,
                  "<text x=\"8\" y=\"%.0f\" fill=\"#d33\">strip %zu: %s at (%g, %g) mm, %g x %g mm</text>\n",
                  h_draw + 22.0 * static_cast<double>(i + 1), i + 1, axis_upper(s.measures).c_str(), s.center_mm[0],
                  s.center_mm[1], s.length_mm, s.width_mm);
    o += b;
  }
  std::snprintf(b, sizeof b,
                "<text x=\"8\" y=\"%.0f\">%s: the path (grey) and the PSD strips (red), program coordinates, "
                "plane %s</text>\n</svg>\n",
                h - 12.0, dsp::program_kind_name(p.kind), p.plane.c_str());
  return o + b;
}

}  // namespace eical::tools::plan
