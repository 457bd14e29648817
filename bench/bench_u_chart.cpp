// The chart of U(G) over radius × feed × strips that README.md shows: eical plan's
// prediction (tools/plan/predicted_uncertainty.hpp) of a circular test, both directions,
// with the sensors identified on site first, on a grid of designs. Prints a Markdown table
// and writes the chart as SVG; a design that runs longer than --max-duration is left out.
//   bench_u_chart [--draws 60] [--repeats 2] [--psd none,B,B4,B8,B16,R16] [--svg docs/u-of-g.svg]
//                 [--max-duration 120]
#include "tools/plan/predicted_uncertainty.hpp"
#include "tools/plan/psd_layouts.hpp"
#include "tools/report/svg.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace {

using eical::tools::plan::TestProgram;

constexpr double kClip_um = 50.0;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("U(G) over radius x feed x strips, as eical plan predicts it");
  int draws = 60, repeats = 2;
  double max_duration_s = 120.0;
  std::string svg_path;
  std::vector<double> radii{10.0, 25.0, 50.0, 100.0, 150.0}, feeds{1000.0, 2500.0, 4000.0, 10000.0};
  std::vector<std::string> layouts{"none", "B", "B4", "B8", "B16", "R16"};
  app.add_option("--draws", draws, "Monte Carlo draws per prediction");
  app.add_option("--repeats", repeats, "revolutions per direction");
  app.add_option("--max-duration", max_duration_s, "designs that run longer (s) are left out");
  app.add_option("--svg", svg_path, "write the chart here");
  app.add_option("--radii", radii, "radii, mm")->delimiter(',');
  app.add_option("--feeds", feeds, "feeds, mm/min")->delimiter(',');
  app.add_option("--psd", layouts, "strip layouts, as eical plan --psd takes them")
      ->delimiter(',')
      ->check(CLI::IsMember(eical::tools::plan::psd_layout_names()));
  CLI11_PARSE(app, argc, argv);

  // u[layout][feed] = U(G) per radius (NaN: left out).
  std::map<std::string, std::map<double, std::vector<double>>> u;
  std::printf("| --psd | feed (mm/min) |");
  for (double r : radii) std::printf(" R%g |", r);
  std::printf("\n|---|---|");
  for (std::size_t i = 0; i < radii.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const std::string& n : layouts)
    for (double f : feeds) {
      std::printf("| %s | %g |", n.c_str(), f);
      const auto layout = eical::tools::plan::psd_layout(n);
      for (double r : radii) {
        TestProgram p;
        p.kind = eical::dsp::ProgramKind::circle, p.direction = "both", p.radius_mm = r, p.feed_mm_min = f,
        p.repeats = repeats;
        p.psd = eical::tools::plan::strips_for(p, layout.strips, layout.facing);
        p.identified = true;
        double g = NAN;
        if (eical::tools::plan::program_duration_s(p) <= max_duration_s) {
          const auto pred = eical::tools::plan::predict(p, 1, draws);
          const auto it = pred.u_k2.find("circle.circular_deviation_G_um");
          if (it != pred.u_k2.end()) g = it->second;
        }
        u[n][f].push_back(g);
        if (std::isfinite(g))
          std::printf(" %.1f |", g);
        else
          std::printf(" — |");
        std::fflush(stdout);
      }
      std::printf("\n");
    }
  if (svg_path.empty()) return 0;
  const char* colours[] = {eical::tools::report::kBlue, eical::tools::report::kGreen, eical::tools::report::kRed,
                           "#8e44ad"};
  std::ofstream os(svg_path);
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"700\" height=\"" << 420 * layouts.size() << "\">\n";
  double y0 = 0.0;
  for (const std::string& n : layouts) {
    const auto layout = eical::tools::plan::psd_layout(n);
    std::vector<eical::tools::report::LineSeries> series;
    int c = 0;
    for (double f : feeds) {
      eical::tools::report::LineSeries s;
      s.label = "F" + std::to_string(static_cast<int>(f)) + " mm/min";
      s.color = colours[c++ % 4];
      // Clipped at kClip_um: the region that decides a verdict stays readable (the table
      // printed above has every value).
      for (std::size_t i = 0; i < radii.size(); ++i)
        if (std::isfinite(u[n][f][i])) s.x.push_back(radii[i]), s.y.push_back(std::min(u[n][f][i], kClip_um));
      series.push_back(s);
    }
    for (const auto& [level, label] :
         {std::pair{10.0, "10 µm: what a circle must resolve"}, std::pair{2.0, "2 µm: ballbar class"}}) {
      eical::tools::report::LineSeries s;
      s.label = label, s.color = eical::tools::report::kGrey, s.dashed = true;
      s.x = {radii.front(), radii.back()}, s.y = {level, level};
      series.push_back(s);
    }
    os << "<g transform=\"translate(0," << y0 << ")\">"
       << eical::tools::report::line_plot(series,
                                          "U(G), k = 2, circle both directions, sensors identified, " +
                                              std::to_string(layout.strips) + " PSD strips" +
                                              (layout.facing == eical::sim::StripFacing::across_path ? ", radial" : ""),
                                          "radius (mm)", "U(G) (µm, clipped at 50)")
       << "</g>\n";
    y0 += 420.0;
  }
  os << "</svg>\n";
  return os ? 0 : 1;
}
