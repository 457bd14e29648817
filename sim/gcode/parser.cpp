#include "sim/gcode/parser.hpp"

#include "dsp/core/error.hpp"
#include "sim/gcode/dialect_codes.hpp"
#include "sim/gcode/words.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace eical::sim::gcode {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInchMm = 25.4;
// The largest number a word carries (words.cpp), for a feed after its unit conversion.
constexpr double kMaxFeedMmMin = 1e9;

// Axis index pairs (u, v) of each plane and the normal axis; ccw is positive about the normal.
struct PlaneAxes {
  int u, v, normal;
};
constexpr PlaneAxes axes_of(Plane p) {
  switch (p) {
    case Plane::xy: return {0, 1, 2};
    case Plane::zx: return {2, 0, 1};
    case Plane::yz: return {1, 2, 0};
  }
  return {0, 1, 2};
}

bool is_code(double value, double code) { return std::abs(value - code) < 1e-9; }

std::string read_as(Dialect d) {
  return std::string("this file is read as ") + dialect_title(d) + " (choose the control with --dialect)";
}

// The modal state: what a block leaves behind for the next.
struct Modal {
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  Plane plane = Plane::xy;
  bool absolute = true;         // G90
  bool arc_absolute = false;    // G90.1 / G91.1 (LinuxCNC default: incremental I/J/K)
  double length_unit_mm = 1.0;  // per programmed length unit: 25.4 after G20 (SINUMERIK G70)
  double feed_unit_mm = 1.0;    // per programmed feed length unit (SINUMERIK: G700 only)
  int motion = -1;              // modal motion G0..G3, -1 = none yet
  double feed_mm_min = 0.0;
  std::optional<Eigen::Vector3d> circle_centre_mm;  // HEIDENHAIN CC (I/J/K)
  double spindle_rpm = 0.0;                         // last S outside a dwell block
  bool spindle_on = false;                          // M3/M4 until M5
};

// One block's words: G- and M-codes in their order, the other words by letter.
struct Block {
  const std::vector<Word>& words;
  std::array<std::optional<Word>, 26> value{};  // non-G/M words by letter
  std::vector<Word> gcodes, mcodes;
  [[nodiscard]] const std::optional<Word>& word(char l) const { return value[static_cast<std::size_t>(l - 'A')]; }
  std::optional<Word> take(char l) { return std::exchange(value[static_cast<std::size_t>(l - 'A')], std::nullopt); }
};

class BlockReader {
 public:
  BlockReader(const SourceLine& at, const ParseOptions& o, Modal& m, Program& p)
      : at_(at), o_(o), d_(o.dialect), m_(m), program_(p) {}

  // One block, executed in LinuxCNC's order: modal G-codes and the feed, user M-codes,
  // dwell, then motion.
  void run(const std::vector<Word>& words) {
    Block b = sort_words(words);
    const BlockCodes codes = apply_gcodes(b);
    if (codes.dwell) add_dwell(b);  // takes the dwell's words out of the block first
    if (const auto& f = b.word('F')) {
      if (!(f->value > 0.0)) at_.fail(f->column, "feed F must be positive");
      m_.feed_mm_min = f->value * m_.feed_unit_mm;
      // In inch a feed the word range takes can exceed it in mm/min, and the canonical text
      // (in mm) would not read back (fuzz finding, gcode_fanuc).
      if (m_.feed_mm_min > kMaxFeedMmMin) {
        char msg[64];
        std::snprintf(msg, sizeof msg, "feed F is out of range (%.0f mm/min)", m_.feed_mm_min);
        at_.fail(f->column, msg);
      }
    }
    if (const auto& s = b.word('S')) m_.spindle_rpm = s->value;
    add_triggers(b);
    check_p_q(b, codes.dwell);
    if (d_ == Dialect::heidenhain_iso) set_circle_centre(b);

    if (codes.motion >= 0) m_.motion = codes.motion;
    const bool has_axis = b.word('X') || b.word('Y') || b.word('Z');
    const bool has_arc_words = b.word('I') || b.word('J') || b.word('K') || b.word('R');
    if (!has_axis && !has_arc_words) return;
    if (codes.dwell) at_.fail(first_of(b, "XYZIJKR"), "G4 and a motion in one block");
    if (m_.motion < 0) at_.fail(words.front().column, "axis words without a motion mode (G0/G1/G2/G3)");
    const Eigen::Vector3d target = target_of(b);
    if (m_.motion == 0 || m_.motion == 1)
      add_linear(b, target);
    else
      add_arc(b, target);
    m_.pos = target;
  }

 private:
  struct BlockCodes {
    bool dwell = false;
    int motion = -1;  // G0..G3 in this block, -1 = none
  };

  int first_of(const Block& b, const char* letters) const {
    for (const char* l = letters; *l; ++l)
      if (b.word(*l)) return b.word(*l)->column;
    return 1;
  }

  Block sort_words(const std::vector<Word>& words) const {
    Block b{words, {}, {}, {}};
    for (const Word& w : words) {
      switch (w.letter) {
        case 'G': b.gcodes.push_back(w); break;
        case 'M': b.mcodes.push_back(w); break;
        case 'N': break;  // block number
        case 'O': break;  // program number (FANUC O1000; words.cpp refuses it elsewhere)
        case 'T': break;  // tool number: no effect on the path
        case 'X':
        case 'Y':
        case 'Z':
        case 'I':
        case 'J':
        case 'K':
        case 'R': check_decimal_point(w); [[fallthrough]];
        case 'F':
        case 'P':
        case 'Q':
        case 'S': {
          auto& slot = b.value[static_cast<std::size_t>(w.letter - 'A')];
          if (slot) at_.fail(w.column, "word '" + std::string(1, w.letter) + "' appears twice in one block");
          slot = w;
          break;
        }
        default: at_.fail(w.column, "unsupported word '" + std::string(1, w.letter) + "'");
      }
    }
    return b;
  }

  // FANUC counts a number without a decimal point in least input increments (X10 is
  // 0.010 mm) unless parameter 3401#0 says otherwise: a length without "." is ambiguous.
  void check_decimal_point(const Word& w) const {
    if (d_ != Dialect::fanuc || w.decimal_point) return;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%c%g", w.letter, w.value);
    at_.fail(w.column, std::string("FANUC reads ") + buf + " without a decimal point as least input increments (or " +
                           "as mm, by parameter 3401#0): write " + buf + ". with the point");
  }

  BlockCodes apply_gcodes(const Block& b) {
    BlockCodes codes;
    for (const Word& g : b.gcodes) {
      const GMeaning meaning = g_meaning(g.value, d_);
      switch (meaning.action) {
        case GAction::motion:
          if (codes.motion >= 0) at_.fail(g.column, "two motion G-codes in one block");
          codes.motion = meaning.motion;
          break;
        case GAction::dwell: codes.dwell = true; break;
        case GAction::plane_xy: m_.plane = Plane::xy; break;
        case GAction::plane_zx: m_.plane = Plane::zx; break;
        case GAction::plane_yz: m_.plane = Plane::yz; break;
        case GAction::inch_positions: m_.length_unit_mm = kInchMm; break;
        case GAction::metric_positions: m_.length_unit_mm = 1.0; break;
        case GAction::inch: m_.length_unit_mm = m_.feed_unit_mm = kInchMm; break;
        case GAction::metric: m_.length_unit_mm = m_.feed_unit_mm = 1.0; break;
        case GAction::exact_stop: program_.exact_stop = true; break;
        case GAction::continuous_path: program_.exact_stop = false; break;
        case GAction::absolute: m_.absolute = true; break;
        case GAction::incremental: m_.absolute = false; break;
        case GAction::arc_centre_absolute: m_.arc_absolute = true; break;
        case GAction::arc_centre_incremental: m_.arc_absolute = false; break;
        case GAction::feed_per_minute: break;    // the only feed mode supported
        case GAction::cancel: break;             // the state eical simulates (the programmed point)
        case GAction::first_work_offset: break;  // the program's coordinates are the set-point
        case GAction::unsupported: {
          char buf[32];
          std::snprintf(buf, sizeof buf, "G%g", g.value);
          at_.fail(g.column, std::string("unsupported G-code ") + buf + other_dialects_hint(g.value, d_));
        }
      }
    }
    return codes;
  }

  // The dwell word of this control and its unit; the word is taken out of the block (a
  // SINUMERIK G4 F is no feed, a FANUC G04 X no axis).
  void add_dwell(Block& b) {
    const int g4_column = b.gcodes.front().column;
    double seconds = kNaN;
    int column = g4_column;
    switch (d_) {
      case Dialect::linuxcnc:
        if (auto p = b.take('P')) seconds = p->value, column = p->column;
        break;
      case Dialect::fanuc:
        if (auto p = b.take('P')) {
          if (p->decimal_point)
            at_.fail(p->column,
                     "FANUC's G04 P counts milliseconds without a decimal point (G04 P500 = 0.5 s); "
                     "seconds are G04 X0.5; " +
                         read_as(d_));
          if (b.word('X')) at_.fail(b.word('X')->column, "G04 with both P and X");
          seconds = p->value * 1e-3, column = p->column;
        } else if (auto x = b.take('X')) {
          seconds = x->value, column = x->column;
        }
        break;
      case Dialect::sinumerik:
        if (auto f = b.take('F')) {
          if (b.word('S')) at_.fail(b.word('S')->column, "G4 with both F and S");
          seconds = f->value, column = f->column;
        } else if (auto s = b.take('S')) {
          if (!(m_.spindle_on && m_.spindle_rpm > 0.0))
            at_.fail(s->column, "G4 S counts spindle revolutions: the spindle must turn (M3/M4 with S<rpm> before)");
          seconds = s->value * 60.0 / m_.spindle_rpm, column = s->column;
        }
        break;
      case Dialect::heidenhain_iso:
        if (auto f = b.take('F')) seconds = f->value, column = f->column;
        break;
    }
    if (std::isnan(seconds)) at_.fail(g4_column, missing_dwell_word(b));
    if (!std::isfinite(seconds)) at_.fail(column, "dwell is out of range");
    if (seconds < 0.0) at_.fail(column, "dwell must not be negative");
    program_.blocks.emplace_back(Dwell{seconds});
    program_.source.push_back({at_.line()});
  }

  std::string missing_dwell_word(const Block& b) const {
    static constexpr const char* kWord[] = {"G4 needs P<seconds>", "G04 needs P<milliseconds> or X<seconds>",
                                            "G4 needs F<seconds> or S<spindle revolutions>", "G04 needs F<seconds>"};
    std::string what = kWord[static_cast<int>(d_)];
    if (d_ != Dialect::sinumerik && d_ != Dialect::heidenhain_iso && b.word('F'))
      what += " (G4 F<seconds> is SINUMERIK's and HEIDENHAIN ISO's dwell; " + read_as(d_) + ")";
    else if ((d_ == Dialect::sinumerik || d_ == Dialect::heidenhain_iso) && b.word('P'))
      what += " (G4 P is LinuxCNC's dwell in seconds, FANUC's in milliseconds; " + read_as(d_) + ")";
    else if (d_ == Dialect::linuxcnc && b.word('X'))
      what += " (G04 X<seconds> is FANUC's dwell; " + read_as(d_) + ")";
    return what;
  }

  // User M-codes (M100..M199) become triggers with their P and Q; the others must be
  // ignorable. M3/M4/M5 switch the spindle (SINUMERIK G4 S counts its revolutions).
  void add_triggers(const Block& b) {
    for (const Word& mw : b.mcodes) {
      const int code = static_cast<int>(std::lround(std::clamp(mw.value, -1e9, 1e9)));
      if (!is_code(mw.value, code)) at_.fail(mw.column, "M-code must be an integer");
      if (code >= 100 && code <= 199) {
        program_.blocks.emplace_back(
            Trigger{code, b.word('P') ? b.word('P')->value : kNaN, b.word('Q') ? b.word('Q')->value : kNaN});
        program_.source.push_back({at_.line()});
      } else if (std::find(o_.ignored_m.begin(), o_.ignored_m.end(), code) == o_.ignored_m.end()) {
        at_.fail(mw.column, "unsupported M-code M" + std::to_string(code));
      }
      if (code == 3 || code == 4) m_.spindle_on = true;
      if (code == 5 || code == 2 || code == 30) m_.spindle_on = false;
    }
  }

  // A P or Q word needs a dwell or a user M-code to belong to.
  void check_p_q(const Block& b, bool dwell) const {
    const bool trigger_in_block =
        std::any_of(b.mcodes.begin(), b.mcodes.end(), [](const Word& m) { return m.value >= 100 && m.value < 200; });
    if (b.word('P') && !trigger_in_block) {
      if (dwell)
        at_.fail(b.word('P')->column,
                 std::string("word 'P' in a ") + dialect_title(d_) + " dwell; " + missing_dwell_word(b));
      at_.fail(b.word('P')->column, "word 'P' without G4 or a user M-code");
    }
    if (b.word('Q') && !trigger_in_block) at_.fail(b.word('Q')->column, "word 'Q' without a user M-code");
  }

  // HEIDENHAIN's I/J/K are the circle centre CC, modal: absolute under G90, from the
  // current position under G91; an axis left out keeps the last centre's (or position's).
  void set_circle_centre(Block& b) {
    Eigen::Vector3d cc = m_.circle_centre_mm.value_or(m_.pos);
    bool any = false;
    for (int a = 0; a < 3; ++a)
      if (auto w = b.take(static_cast<char>('I' + a))) {
        cc[a] = m_.absolute ? w->value * m_.length_unit_mm : m_.pos[a] + w->value * m_.length_unit_mm;
        any = true;
      }
    if (any) m_.circle_centre_mm = cc;
  }

  Eigen::Vector3d target_of(const Block& b) const {
    Eigen::Vector3d target = m_.pos;
    for (int a = 0; a < 3; ++a) {
      if (const auto& w = b.word(static_cast<char>('X' + a)))
        target[a] = m_.absolute ? w->value * m_.length_unit_mm : m_.pos[a] + w->value * m_.length_unit_mm;
    }
    return target;
  }

  void add_linear(const Block& b, const Eigen::Vector3d& target) {
    if (b.word('I') || b.word('J') || b.word('K') || b.word('R'))
      at_.fail(first_of(b, "IJKR"), "arc words I/J/K/R need G2 or G3");
    if (m_.motion == 1 && m_.feed_mm_min <= 0.0) at_.fail(b.words.front().column, "G1 without a feed rate F");
    program_.blocks.emplace_back(Linear{m_.pos, target, m_.feed_mm_min, m_.motion == 0});
    program_.source.push_back({at_.line()});
  }

  // R form: the centre on the chord's normal; the short arc (R > 0) has it left of the chord
  // for ccw, right for cw; R < 0 flips.
  Eigen::Vector2d r_form_centre(const Word& r, const Eigen::Vector2d& s, const Eigen::Vector2d& e, bool cw) const {
    const double radius = std::abs(r.value) * m_.length_unit_mm;
    const Eigen::Vector2d chord = e - s;
    const double d = chord.norm();
    if (d < 1e-12) at_.fail(r.column, "R-form arc needs distinct start and end points");
    if (d / 2.0 > radius + o_.arc_radius_tolerance_mm)
      at_.fail(r.column, "arc radius R is smaller than half the chord");
    const double h = std::sqrt(std::max(0.0, radius * radius - d * d / 4.0));
    const Eigen::Vector2d left(-chord.y() / d, chord.x() / d);  // unit normal to the left of the chord
    const double side = (cw ? -1.0 : 1.0) * (r.value < 0.0 ? -1.0 : 1.0);
    return (s + e) / 2.0 + side * h * left;
  }

  // I/J/K form: offsets from the start (or absolute, G90.1); HEIDENHAIN: the centre CC.
  Eigen::Vector2d centre_of(const Block& b, const PlaneAxes& ax, const Eigen::Vector2d& s) const {
    if (d_ == Dialect::heidenhain_iso) {
      if (!m_.circle_centre_mm)
        at_.fail(b.words.front().column, "G02/G03 without a circle centre (an I/J/K block before it)");
      return {(*m_.circle_centre_mm)[ax.u], (*m_.circle_centre_mm)[ax.v]};
    }
    double off[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 3; ++a)
      if (const auto& w = b.word(static_cast<char>('I' + a))) {
        if (a == ax.normal) at_.fail(w->column, std::string("offset ") + w->letter + " is normal to the arc plane");
        off[a] = w->value * m_.length_unit_mm;
      }
    const Eigen::Vector2d o(off[ax.u], off[ax.v]);
    return m_.arc_absolute ? o : Eigen::Vector2d(s + o);
  }

  // The signed angle from start to end about the centre: negative for cw; the same point
  // is a full turn.
  static double arc_sweep(const Eigen::Vector2d& s, const Eigen::Vector2d& e, const Eigen::Vector2d& c, bool cw) {
    const double a0 = std::atan2(s.y() - c.y(), s.x() - c.x());
    const double a1 = std::atan2(e.y() - c.y(), e.x() - c.x());
    double sweep = a1 - a0;
    if (cw) {
      while (sweep >= -1e-12) sweep -= 2.0 * kPi;  // same point → full clockwise turn
      if (sweep < -2.0 * kPi - 1e-12) sweep += 2.0 * kPi;
    } else {
      while (sweep <= 1e-12) sweep += 2.0 * kPi;
      if (sweep > 2.0 * kPi + 1e-12) sweep -= 2.0 * kPi;
    }
    return sweep;
  }

  // Arcs (G2 clockwise, G3 counter-clockwise about the plane normal).
  void add_arc(const Block& b, const Eigen::Vector3d& target) {
    if (m_.feed_mm_min <= 0.0) at_.fail(b.words.front().column, "arc without a feed rate F");
    const PlaneAxes ax = axes_of(m_.plane);
    const bool cw = m_.motion == 2;
    const Eigen::Vector2d s(m_.pos[ax.u], m_.pos[ax.v]);
    const Eigen::Vector2d e(target[ax.u], target[ax.v]);
    Eigen::Vector2d c;
    if (const auto& r = b.word('R')) {
      if (b.word('I') || b.word('J') || b.word('K')) at_.fail(r->column, "arc with both R and I/J/K");
      c = r_form_centre(*r, s, e, cw);
    } else {
      c = centre_of(b, ax, s);
      const double r_start = (s - c).norm(), r_end = (e - c).norm();
      if (std::abs(r_start - r_end) > o_.arc_radius_tolerance_mm + 4.0 * kWrittenResolutionMm)
        at_.fail(b.words.front().column, "arc end point is not on the circle (radius " + std::to_string(r_start) +
                                             " vs " + std::to_string(r_end) + " mm)");
      if (r_start < 1e-9) at_.fail(b.words.front().column, "arc radius is zero");
    }
    const double sweep = arc_sweep(s, e, c, cw);
    Eigen::Vector3d centre = m_.pos;
    centre[ax.u] = c.x();
    centre[ax.v] = c.y();
    program_.blocks.emplace_back(Arc{m_.pos, target, centre, m_.plane, cw, sweep, m_.feed_mm_min});
    program_.source.push_back({at_.line()});
  }

  const SourceLine& at_;
  const ParseOptions& o_;
  Dialect d_;
  Modal& m_;
  Program& program_;
};

}  // namespace

Program parse(std::string_view text, std::string_view name, const ParseOptions& options) {
  Program program;
  program.exact_stop = options.dialect != Dialect::heidenhain_iso;  // the TNC contours continuously
  Modal modal;
  modal.pos = options.start_mm;
  int line_no = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(begin, end - begin);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++line_no;
    begin = end + 1;
    const SourceLine at(name, line_no);
    const std::vector<Word> words = split_words(line, options.dialect, at);
    if (words.empty()) {
      if (end == text.size()) break;
      continue;
    }
    BlockReader(at, options, modal, program).run(words);
  }
  return program;
}

void require_motion(const Program& program, std::string_view name) {
  for (const auto& b : program.blocks)
    if (std::holds_alternative<Linear>(b) || std::holds_alternative<Arc>(b)) return;
  throw dsp::InputError(std::string(name) + ": the program has no motion (no G0/G1/G2/G3 move)" +
                        (program.blocks.empty() ? ": the file is empty or holds comments only" : "") +
                        "; a calibration needs a program that moves the machine");
}

}  // namespace eical::sim::gcode
