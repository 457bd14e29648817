// Property: a random program (rapid and feed moves, arcs both ways in every plane, full
// circles, incremental moves, feeds, dwells, M-codes, comments) written for each control
// by eical's dialect writer and read back by its reader is the same program: the paths
// within 1 µm, the dwells within 1 ms, the same feeds and triggers. And again through the
// canonical text the simulator keeps.
#include "sim/gcode/canonical.hpp"
#include "sim/gcode/dialect.hpp"
#include "sim/gcode/format.hpp"
#include "sim/gcode/parser.hpp"
#include "tests/support/gcode_compare.hpp"

#include <gtest/gtest.h>
#include <numbers>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace eical::sim::gcode {
namespace {

std::string num(double v) { return format_number("%.4f", v); }

// A program in the canonical (LinuxCNC) form, as eical's generators write it.
std::string random_program(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> coord(-200.0, 200.0), unit(0.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 9), plane_pick(0, 2), feed_pick(1, 120);
  const char* planes[] = {"G17", "G18", "G19"};
  const int plane_axes[3][2] = {{0, 1}, {2, 0}, {1, 2}};  // (u, v): ccw from +normal
  double pos[3] = {coord(rng), coord(rng), coord(rng)};
  std::string g = std::string("G90 G21 G17 ") + (unit(rng) < 0.5 ? "G61" : "G64") + " (random program)\n";
  g += "G0 X" + num(pos[0]) + " Y" + num(pos[1]) + " Z" + num(pos[2]) + "\n";
  bool has_feed = false;
  auto feed = [&] {
    has_feed = true;
    return " F" + std::to_string(50 * feed_pick(rng));
  };
  const int n = 10 + static_cast<int>(unit(rng) * 40);
  for (int i = 0; i < n; ++i) {
    const int k = kind(rng);
    if (k <= 1) {  // rapid or feed move, absolute; sometimes one axis only
      std::string words;
      for (int a = 0; a < 3; ++a)
        if (a == 0 || unit(rng) < 0.6) {
          pos[a] = std::round(coord(rng) * 1e4) / 1e4;
          words += std::string(" ") + static_cast<char>('X' + a) + num(pos[a]);
        }
      g += (k == 0 ? "G0" : "G1") + words + (k == 1 ? feed() : "") + "\n";
    } else if (k == 2) {  // incremental feed move, back to absolute
      const int a = plane_pick(rng);
      const double step = std::round((coord(rng) / 4.0) * 1e4) / 1e4;
      pos[a] += step;
      g += std::string("G91 G1 ") + static_cast<char>('X' + a) + num(step) + feed() + "\nG90\n";
    } else if (k <= 5) {  // arc in a plane: quarter to full turn, either way, sometimes helical
      const int p = plane_pick(rng), u = plane_axes[p][0], v = plane_axes[p][1], nrm = 3 - u - v;
      const double r = 1.0 + unit(rng) * 60.0, a0 = unit(rng) * 2.0 * std::numbers::pi;
      const bool full = unit(rng) < 0.25, cw = unit(rng) < 0.5;
      const double sweep = full ? 0.0 : (0.2 + unit(rng) * 5.8) * (cw ? -1.0 : 1.0);
      const double cu = pos[u] - r * std::cos(a0), cv = pos[v] - r * std::sin(a0);
      double end[3] = {pos[0], pos[1], pos[2]};
      end[u] = std::round((cu + r * std::cos(a0 + sweep)) * 1e4) / 1e4;
      end[v] = std::round((cv + r * std::sin(a0 + sweep)) * 1e4) / 1e4;
      if (full) end[u] = pos[u], end[v] = pos[v];
      std::string words =
          std::string(" ") + static_cast<char>('X' + u) + num(end[u]) + " " + static_cast<char>('X' + v) + num(end[v]);
      if (unit(rng) < 0.2) {
        end[nrm] = std::round((pos[nrm] + coord(rng) / 10.0) * 1e4) / 1e4;
        words += std::string(" ") + static_cast<char>('X' + nrm) + num(end[nrm]);
      }
      words += std::string(" ") + static_cast<char>('I' + u) + num(cu - pos[u]) + " " + static_cast<char>('I' + v) +
               num(cv - pos[v]);
      g += std::string(planes[p]) + "\n" + (cw ? "G2" : "G3") + words + (has_feed && unit(rng) < 0.5 ? "" : feed()) +
           "\n";
      for (int a = 0; a < 3; ++a) pos[a] = end[a];
    } else if (k <= 7) {  // dwell, whole milliseconds (FANUC's resolution) or finer
      g += "G4 P" + format_number(unit(rng) < 0.5 ? "%.3f" : "%.4f", unit(rng) * 3.0) + "\n";
    } else {
      const char* m[] = {"M101", "M102", "M103", "M3", "M5", "M8", "M9"};
      g += std::string(m[static_cast<int>(unit(rng) * 7) % 7]) + (unit(rng) < 0.3 ? " (mark)" : "") + "\n";
    }
  }
  return g;
}

}  // namespace

TEST(GcodeDialectProperty, RandomProgramsReadBackInEveryDialect) {
  const ProgramIdentity id{1234, "EICAL_RANDOM", "random program"};
  double worst_path_um[4] = {}, worst_dwell_ms[4] = {};
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    std::mt19937_64 rng(seed);
    const std::string canonical = random_program(rng);
    const Program want = parse(canonical, "canonical");
    for (Dialect d : {Dialect::linuxcnc, Dialect::fanuc, Dialect::sinumerik, Dialect::heidenhain_iso}) {
      const int di = static_cast<int>(d);
      const std::string text = write_dialect(canonical, d, id);
      SCOPED_TRACE(std::string(dialect_name(d)) + ", seed " + std::to_string(seed) + ":\n" + text);
      Program got;
      ASSERT_NO_THROW(got = parse(text, "written", {.dialect = d}));
      test::ProgramDifference diff = test::compare_programs(want, got);
      EXPECT_EQ(diff.mismatch, "");
      EXPECT_LE(diff.path_um, 1.0);
      EXPECT_LE(diff.dwell_ms, 1.0);
      worst_path_um[di] = std::max(worst_path_um[di], diff.path_um);
      worst_dwell_ms[di] = std::max(worst_dwell_ms[di], diff.dwell_ms);
      if (d != Dialect::heidenhain_iso) {
        EXPECT_EQ(got.exact_stop, want.exact_stop);
      }
      // The canonical text the simulator keeps of it runs the same program (from where the
      // program's first rapid move puts the machine, as the simulator does).
      const std::string kept = canonical_gcode(text, "written", d);
      const Eigen::Vector3d start = std::get<Linear>(want.blocks.front()).to_mm;
      diff = test::compare_programs(parse(canonical, "canonical", {.start_mm = start}),
                                    parse(kept, "kept", {.start_mm = start}));
      EXPECT_EQ(diff.mismatch, "") << kept;
      EXPECT_LE(diff.path_um, 1.0);
      EXPECT_LE(diff.dwell_ms, 1.0);
    }
  }
  for (Dialect d : {Dialect::linuxcnc, Dialect::fanuc, Dialect::sinumerik, Dialect::heidenhain_iso})
    std::printf("random programs, %-14s worst path %.4f um, worst dwell %.4f ms\n", dialect_name(d),
                worst_path_um[static_cast<int>(d)], worst_dwell_ms[static_cast<int>(d)]);
}

}  // namespace eical::sim::gcode
