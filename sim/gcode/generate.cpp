#include "sim/gcode/generate.hpp"
#include "sim/gcode/format.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::sim::gcode {
namespace {

struct PlaneWords {
  const char* g;  // G17 / G18 / G19
  char a, b;      // the two plane axes, counter-clockwise order seen from +normal
  char ia, ib;    // their centre-offset words
};

PlaneWords plane_axes(const std::string& plane) {
  if (plane == "xy") return {"G17", 'X', 'Y', 'I', 'J'};
  if (plane == "zx") return {"G18", 'Z', 'X', 'K', 'I'};
  if (plane == "yz") return {"G19", 'Y', 'Z', 'J', 'K'};
  throw dsp::InputError("program plane '" + plane + "' is not xy, zx or yz");
}

std::string num(double v) { return format_number("%.4f", std::abs(v) < 5e-5 ? 0.0 : v); }

void require(bool ok, const std::string& what) {
  if (!ok) throw dsp::InputError("program: " + what);
}

std::string header(const char* mode_comment, const std::string& plane_g, bool exact) {
  return std::string("G90 G21 ") + plane_g + (exact ? " G61" : " G64") + " (" + mode_comment + ")\n";
}

std::string start(const RestTimes& r) {
  return "G4 P" + format_number("%.3g", r.before_start_s) + "\nM101\nG4 P" + format_number("%.3g", r.after_start_s) +
         "\n";
}
std::string finish(const RestTimes& r) {
  return "G4 P" + format_number("%.3g", r.before_end_s) + "\nM103\nG4 P" + format_number("%.3g", r.after_end_s) + "\n";
}

char axis_letter(const std::string& axis) {
  require(axis == "x" || axis == "y" || axis == "z", "axis '" + axis + "' is not x, y or z");
  return static_cast<char>(std::toupper(axis[0]));
}

}  // namespace

double partial_arc_start_deg(const dsp::Program& p) {
  // Default: the arc symmetric about the plane's +second axis (90°), as a ballbar's 220°
  // arc in a vertical plane stays above the table: −20° … 200°.
  return p.arc_start_deg ? *p.arc_start_deg : 90.0 - p.arc_deg / 2.0;
}

double partial_arc_ramp_deg(const dsp::Program& p) { return std::min(45.0, (360.0 - p.arc_deg) / 2.0); }

std::string circle_program(const dsp::Program& p, const RestTimes& rest) {
  require(p.radius_mm > 0.0, "radius_mm must be positive");
  require(p.feed_mm_min > 0.0, "feed_mm_min must be positive");
  require(p.repeats >= 1, "repeats must be at least 1");
  require(p.direction == "ccw" || p.direction == "cw" || p.direction == "both", "direction must be cw, ccw or both");
  require(p.arc_deg > 0.0 && p.arc_deg <= 360.0, "arc_deg must be in (0, 360]");
  const bool partial = p.arc_deg < 360.0;
  // A partial arc needs room for its ramp arcs outside the evaluated arc (feed constant
  // over the whole evaluated arc).
  require(!partial || partial_arc_ramp_deg(p) >= 10.0,
          "a partial arc must leave at least 20 deg for the ramps (arc_deg <= 340)");
  const PlaneWords ax = plane_axes(p.plane);
  const double r = p.radius_mm, c0 = p.center_mm[0], c1 = p.center_mm[1];
  constexpr double deg = std::numbers::pi / 180.0;
  auto pt = [&](double ang) { return std::pair{c0 + r * std::cos(ang), c1 + r * std::sin(ang)}; };
  auto arc = [&](bool ccw, double from, double to, const char* comment, bool with_feed) {
    const auto [fa, fb] = pt(from);
    const auto [ta, tb] = pt(to);
    std::string line = std::string(ccw ? "G3 " : "G2 ") + ax.a + num(ta) + " " + ax.b + num(tb) + " " + ax.ia +
                       num(c0 - fa) + " " + ax.ib + num(c1 - fb);
    if (with_feed) line += " F" + format_number("%.0f", p.feed_mm_min);
    if (comment[0]) line += std::string(" (") + comment + ")";
    return line + "\n";
  };
  const std::string reversal = "G4 P0.2 (reversal: rest before the opposite direction)\n";
  std::string g = header("continuous path: the arcs are one blended move", ax.g, false);
  if (!partial) {
    // Start at 45°; the ramp-in quarter ends at 135° (ccw) or −45° (cw): the revolutions
    // then start and end there, so every one of them runs at full feed. "both" runs the
    // ccw revolutions, rests, and comes back clockwise over the same quarters.
    const double a0 = std::numbers::pi / 4, q = std::numbers::pi / 2;
    auto revolutions = [&](bool ccw, double from) {
      const double step = ccw ? q : -q, rev_start = from + step;
      std::string s = arc(ccw, from, rev_start, "ramp-in", true);
      for (int k = 0; k < p.repeats; ++k) s += "M102\n" + arc(ccw, rev_start, rev_start, "", false);  // end = start
      return s + "M102\n" + arc(ccw, rev_start, rev_start + step, "ramp-out", false);
    };
    const auto [sa, sb] = pt(a0);
    g += std::string("G0 ") + ax.a + num(sa) + " " + ax.b + num(sb) + "\n" + start(rest);
    if (p.direction == "both")
      g += revolutions(true, a0) + reversal + revolutions(false, a0 + 2 * q);
    else
      g += revolutions(p.direction == "ccw", a0);
    return g + finish(rest);
  }
  // Partial arc (ISO 230-4 allows arcs below 360°): ramp-in arc, M102, the evaluated arc,
  // M102, ramp-out arc. Repeats of one direction come back over the arc without marks.
  const double s0 = partial_arc_start_deg(p) * deg, s1 = s0 + p.arc_deg * deg, ramp = partial_arc_ramp_deg(p) * deg;
  auto sweep_ccw = [&](bool feed) {
    return arc(true, s0 - ramp, s0, "ramp-in", feed) + "M102\n" + arc(true, s0, s1, "evaluated arc", false) + "M102\n" +
           arc(true, s1, s1 + ramp, "ramp-out", false);
  };
  auto sweep_cw = [&](bool feed) {
    return arc(false, s1 + ramp, s1, "ramp-in", feed) + "M102\n" + arc(false, s1, s0, "evaluated arc", false) +
           "M102\n" + arc(false, s0, s0 - ramp, "ramp-out", false);
  };
  const bool cw_first = p.direction == "cw";
  const auto [sa, sb] = pt(cw_first ? s1 + ramp : s0 - ramp);
  g += std::string("G0 ") + ax.a + num(sa) + " " + ax.b + num(sb) + "\n" + start(rest);
  for (int k = 0; k < p.repeats; ++k) {
    if (k > 0) g += reversal;
    if (p.direction == "both")
      g += sweep_ccw(k == 0) + reversal + sweep_cw(false);
    else if (cw_first)
      g += sweep_cw(k == 0) + (k + 1 < p.repeats ? reversal + arc(true, s0 - ramp, s1 + ramp, "back", false) : "");
    else
      g += sweep_ccw(k == 0) + (k + 1 < p.repeats ? reversal + arc(false, s1 + ramp, s0 - ramp, "back", false) : "");
  }
  return g + finish(rest);
}

std::string positioning_program(const dsp::Program& p, double overrun_mm, const RestTimes& rest) {
  require(p.targets_mm.size() >= 2, "positioning needs at least 2 targets");
  require(std::is_sorted(p.targets_mm.begin(), p.targets_mm.end()), "targets_mm must be ascending");
  require(p.runs >= 1, "runs must be at least 1");
  require(p.feed_mm_min > 0.0, "feed_mm_min must be positive");
  require(overrun_mm >= 0.0, "overrun must not be negative");
  const char a = axis_letter(p.axis);
  const std::string f = " F" + format_number("%.0f", p.feed_mm_min);
  const std::string dwell = "G4 P" + format_number("%.3g", p.dwell_s > 0 ? p.dwell_s : 0.5) + "\n";
  std::string g = header("ISO 230-2 linear cycle, exact stop", "G17", true);
  g += std::string("G0 ") + a + num(p.targets_mm.front() - overrun_mm) + "\n";
  g += start(rest);
  for (int run = 0; run < p.runs; ++run) {
    for (double t : p.targets_mm) g += std::string("G1 ") + a + num(t) + f + "\nM102\n" + dwell;
    g += std::string("G1 ") + a + num(p.targets_mm.back() + overrun_mm) + f + " (overrun, reversal)\n";
    for (auto it = p.targets_mm.rbegin(); it != p.targets_mm.rend(); ++it)
      g += std::string("G1 ") + a + num(*it) + f + "\nM102\n" + dwell;
    g += std::string("G1 ") + a + num(p.targets_mm.front() - overrun_mm) + f + " (overrun, reversal)\n";
  }
  g += finish(rest);
  return g;
}

std::string step_program(const dsp::Program& p, const RestTimes& rest) {
  require(p.targets_mm.size() == 2, "step needs targets_mm = [a, b]");
  require(p.runs >= 1, "runs must be at least 1");
  require(p.feed_mm_min > 0.0, "feed_mm_min must be positive");
  const char a = axis_letter(p.axis);
  const std::string f = " F" + format_number("%.0f", p.feed_mm_min);
  const std::string dwell = "G4 P" + format_number("%.3g", p.dwell_s > 0 ? p.dwell_s : 0.5) + "\n";
  // Approach the first target, then the rest before M101 (the recorded step runs, made
  // without it, started standing there).
  std::string g = header("absolute, mm, XY plane, exact stop", "G17", true);
  g += std::string("G0 ") + a + num(p.targets_mm[0]) + " (approach)\n";
  g += start(rest);
  for (int run = 0; run < p.runs; ++run) {
    g += std::string("G1 ") + a + num(p.targets_mm[1]) + f + "\nM102\n" + dwell;
    g += std::string("G1 ") + a + num(p.targets_mm[0]) + f + "\nM102\n" + dwell;
  }
  g += finish(rest);
  return g;
}

std::string rectangle_program(const dsp::Program& p, const RestTimes& rest) {
  require(p.size_mm[0] > 0.0 && p.size_mm[1] > 0.0, "size_mm must be positive");
  require(p.feed_mm_min > 0.0, "feed_mm_min must be positive");
  require(p.repeats >= 1, "repeats must be at least 1");
  const PlaneWords ax = plane_axes(p.plane);
  const double x0 = p.corner_mm[0], y0 = p.corner_mm[1], x1 = x0 + p.size_mm[0], y1 = y0 + p.size_mm[1];
  const std::string f = " F" + format_number("%.0f", p.feed_mm_min);
  const std::string dwell = "G4 P" + format_number("%.3g", p.dwell_s > 0 ? p.dwell_s : 0.2) + "\n";
  auto go = [&](double a, double b) {
    return std::string("G1 ") + ax.a + num(a) + " " + ax.b + num(b) + f + "\nM102\n" + dwell;
  };
  std::string g = header("rectangle, exact stop at the corners", ax.g, true);
  g += std::string("G0 ") + ax.a + num(x0) + " " + ax.b + num(y0) + "\n";
  g += start(rest);
  for (int k = 0; k < p.repeats; ++k) g += go(x1, y0) + go(x1, y1) + go(x0, y1) + go(x0, y0);
  g += finish(rest);
  return g;
}

Swing strip_swing(const IdentifyPlan& plan, const dsp::PsdSpec& strip) {
  const int along = strip.measures == "x" ? 0 : 1;
  Swing w{strip.center_mm[along], plan.swing_mm / 2.0};
  if (const auto& t = plan.travel_mm[along]) {
    require(t->hi_mm > t->lo_mm, "identify: a travel's end lies above its start");
    require(strip.center_mm[along] >= t->lo_mm && strip.center_mm[along] <= t->hi_mm,
            "identify: the strip measuring " + strip.measures + " at " + num(strip.center_mm[along]) +
                " mm lies outside the travel " + num(t->lo_mm) + " … " + num(t->hi_mm) + " mm");
    if (t->hi_mm - t->lo_mm >= plan.swing_mm)
      w.centre_mm = std::clamp(w.centre_mm, t->lo_mm + w.half_mm, t->hi_mm - w.half_mm);
    else  // the lever the scale needs is longer than the test: centred on its travel
      w.centre_mm = 0.5 * (t->lo_mm + t->hi_mm);
    // Each swing must carry the light spot over the whole strip at every feed: a swing that
    // turns on the strip gives no crossing, and identify then refuses the run.
    const double reach_mm = std::abs(strip.center_mm[along] - w.centre_mm) + 0.5 * strip.length_mm;
    require(reach_mm <= w.half_mm + 1e-9,
            "identify: the strip measuring " + strip.measures + " at " + format_number("%g", strip.center_mm[along]) +
                " mm lies " +
                format_number("%g", std::min(strip.center_mm[along] - t->lo_mm, t->hi_mm - strip.center_mm[along])) +
                " mm inside the travel " + format_number("%g", t->lo_mm) + " … " + format_number("%g", t->hi_mm) +
                " mm: a swing inside the travel cannot cross its " + format_number("%g", strip.length_mm) +
                " mm; mount it at least " + format_number("%g", 0.5 * strip.length_mm) + " mm inside");
  }
  return w;
}

std::string identify_program(const IdentifyPlan& plan, const RestTimes& rest) {
  require(!plan.psd.empty() || !plan.axes.empty(), "identify needs a PSD strip or an axis to swing");
  require(plan.swing_mm > 0.0 && !plan.feeds_mm_min.empty(), "identify needs a swing and feeds");
  const double half = plan.swing_mm / 2.0;
  std::string g = header("on-site identification: swings across the PSD strips at rising feeds", "G17", true);
  const std::string dwell = "M102\nG4 P" + format_number("%.3g", plan.dwell_s) + "\n";
  auto swings = [&](char a, const Swing& w) {
    std::string s;
    for (double feed : plan.feeds_mm_min) {
      const std::string f = " F" + format_number("%.0f", feed);
      s += std::string("G1 ") + a + num(w.centre_mm + w.half_mm) + f + "\n" + dwell;
      s += std::string("G1 ") + a + num(w.centre_mm - w.half_mm) + f + "\n" + dwell;
    }
    return s;
  };
  bool started = false;
  for (const auto& strip : plan.psd) {
    require(strip.measures == "x" || strip.measures == "y",
            "identify: a PSD strip measures x or y, not '" + strip.measures + "'");
    const char along = axis_letter(strip.measures);
    const char cross = along == 'X' ? 'Y' : 'X';
    const double c_cross = strip.center_mm[cross == 'X' ? 0 : 1];
    const Swing w = strip_swing(plan, strip);
    const std::string to_start = std::string(" ") + along + num(w.centre_mm - w.half_mm) + " " + cross + num(c_cross);
    if (!started) {
      g += "G0" + to_start + "\n" + start(rest);
      started = true;
    } else {
      g += "G1" + to_start + " F3000\n" + dwell;
    }
    g += swings(along, w);
  }
  for (const auto& axis : plan.axes) {
    const char a = axis_letter(axis);
    if (!started) g += start(rest), started = true;
    g += std::string("G91 G1 ") + a + num(-half) + " F3000\nG90\n" + dwell;  // from where it is: relative
    // Back to absolute coordinates is unknown here, so the swings stay relative too.
    for (double feed : plan.feeds_mm_min) {
      const std::string f = " F" + format_number("%.0f", feed);
      g += std::string("G91 G1 ") + a + num(2.0 * half) + f + "\nG90\n" + dwell;
      g += std::string("G91 G1 ") + a + num(-2.0 * half) + f + "\nG90\n" + dwell;
    }
    g += std::string("G91 G1 ") + a + num(half) + " F3000\nG90\n" + dwell;
  }
  g += finish(rest);
  return g;
}

std::string identify_program(const dsp::Program& p, const RestTimes& rest) {
  require(!p.targets_mm.empty(), "identify needs targets_mm = [psd_centre]");
  IdentifyPlan plan;
  dsp::PsdSpec strip;
  strip.measures = p.axis;
  require(p.axis == "x" || p.axis == "y", "identify: a PSD strip measures x or y, not '" + p.axis + "'");
  strip.center_mm[p.axis == "x" ? 0 : 1] = p.targets_mm[0];
  plan.psd.push_back(strip);
  if (p.size_mm[0] > 0.0) plan.swing_mm = p.size_mm[0];
  return identify_program(plan, rest);
}

std::string program_gcode(const dsp::Program& p) {
  switch (p.kind) {
    case dsp::ProgramKind::circle: return circle_program(p);
    case dsp::ProgramKind::positioning: return positioning_program(p);
    case dsp::ProgramKind::step: return step_program(p);
    case dsp::ProgramKind::rectangle: return rectangle_program(p);
    case dsp::ProgramKind::identify: return identify_program(p);
    case dsp::ProgramKind::freeform: break;  // a contour is the user's own NC
  }
  throw dsp::InputError(std::string("program kind '") + dsp::program_kind_name(p.kind) +
                        "' has no generator (circle, positioning, step, rectangle, identify)");
}

}  // namespace eical::sim::gcode
