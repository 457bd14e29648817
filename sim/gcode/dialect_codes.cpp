#include "sim/gcode/dialect_codes.hpp"

#include <array>
#include <cmath>
#include <initializer_list>

namespace eical::sim::gcode {
namespace {

struct Entry {
  double code;
  GAction action;
};

bool is(double value, double code) { return std::abs(value - code) < 1e-9; }

// Codes every control here reads alike.
constexpr std::array kCommon{Entry{4, GAction::dwell},       Entry{17, GAction::plane_xy}, Entry{18, GAction::plane_zx},
                             Entry{19, GAction::plane_yz},   Entry{40, GAction::cancel},   Entry{90, GAction::absolute},
                             Entry{91, GAction::incremental}};

// LinuxCNC G-code reference (G20/G21, G61/G61.1/G64, G90.1/G91.1, G94, G40/G49/G80, G54).
constexpr std::array kLinuxcnc{Entry{20, GAction::inch},
                               Entry{21, GAction::metric},
                               Entry{61, GAction::exact_stop},
                               Entry{61.1, GAction::exact_stop},
                               Entry{64, GAction::continuous_path},
                               Entry{90.1, GAction::arc_centre_absolute},
                               Entry{91.1, GAction::arc_centre_incremental},
                               Entry{94, GAction::feed_per_minute},
                               Entry{49, GAction::cancel},
                               Entry{80, GAction::cancel},
                               Entry{54, GAction::first_work_offset}};
// FANUC milling: the same ISO codes, without LinuxCNC's arc-centre modes (I/J/K are
// always incremental).
constexpr std::array kFanuc{Entry{20, GAction::inch},
                            Entry{21, GAction::metric},
                            Entry{61, GAction::exact_stop},
                            Entry{64, GAction::continuous_path},
                            Entry{94, GAction::feed_per_minute},
                            Entry{49, GAction::cancel},
                            Entry{80, GAction::cancel},
                            Entry{54, GAction::first_work_offset}};
// SINUMERIK (Siemens mode): G70/G71 inch/metric for lengths only, G700/G710 also for the
// feed (SINUMERIK 802D sl / 808D programming manuals, "Dimensions in metric units and
// inches: G71, G70, G710, G700"); G60 exact stop, G64 continuous path.
constexpr std::array kSinumerik{Entry{70, GAction::inch_positions},  Entry{71, GAction::metric_positions},
                                Entry{700, GAction::inch},           Entry{710, GAction::metric},
                                Entry{60, GAction::exact_stop},      Entry{64, GAction::continuous_path},
                                Entry{94, GAction::feed_per_minute}, Entry{54, GAction::first_work_offset}};
// HEIDENHAIN TNC DIN/ISO: G70/G71 inch/mm (in the program's begin line), no modal exact
// stop (the TNC contours continuously).
constexpr std::array kHeidenhain{Entry{70, GAction::inch}, Entry{71, GAction::metric}};

GAction lookup(double code, Dialect d) {
  for (const Entry& e : kCommon)
    if (is(code, e.code)) return e.action;
  auto find = [&](const auto& table) {
    for (const Entry& e : table)
      if (is(code, e.code)) return e.action;
    return GAction::unsupported;
  };
  switch (d) {
    case Dialect::linuxcnc: return find(kLinuxcnc);
    case Dialect::fanuc: return find(kFanuc);
    case Dialect::sinumerik: return find(kSinumerik);
    case Dialect::heidenhain_iso: return find(kHeidenhain);
  }
  return GAction::unsupported;
}

const char* action_text(GAction a) {
  switch (a) {
    case GAction::inch_positions: return "inch lengths";
    case GAction::metric_positions: return "metric lengths";
    case GAction::inch: return "inch";
    case GAction::metric: return "metric";
    case GAction::exact_stop: return "exact stop";
    case GAction::continuous_path: return "continuous path";
    case GAction::arc_centre_absolute: return "absolute arc centres";
    case GAction::arc_centre_incremental: return "incremental arc centres";
    case GAction::feed_per_minute: return "feed per minute";
    case GAction::cancel: return "a cancel code";
    case GAction::first_work_offset: return "the first work offset";
    default: return "a known code";
  }
}

}  // namespace

GMeaning g_meaning(double code, Dialect d) {
  for (int m = 0; m <= 3; ++m)
    if (is(code, m)) return {GAction::motion, m};
  return {lookup(code, d), -1};
}

std::string other_dialects_hint(double code, Dialect d) {
  std::string who;
  GAction meaning = GAction::unsupported;
  for (Dialect o : {Dialect::linuxcnc, Dialect::fanuc, Dialect::sinumerik, Dialect::heidenhain_iso}) {
    if (o == d) continue;
    const GAction a = lookup(code, o);
    if (a == GAction::unsupported) continue;
    who += std::string(who.empty() ? "" : " and ") + dialect_title(o);
    meaning = a;  // the tables agree where two controls share a code
  }
  if (who.empty()) return "";
  return std::string(": ") + who + " mean" + (who.find(" and ") == std::string::npos ? "s " : " ") +
         action_text(meaning) + " by it; this file is read as " + dialect_title(d) +
         " (choose the control with --dialect)";
}

}  // namespace eical::sim::gcode
