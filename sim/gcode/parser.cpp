#include "sim/gcode/parser.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

namespace eical::sim::gcode {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Word {
  char letter;
  double value;
  int column;  // 1-based
};

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

class LineParser {
 public:
  LineParser(std::string_view name, int line) : name_(name), line_(line) {}

  [[noreturn]] void fail(int column, const std::string& what) const {
    throw dsp::InputError(std::string(name_) + ":" + std::to_string(line_) + ":" + std::to_string(column) + ": " +
                          what);
  }

  // Splits one line into words, dropping comments, block delete and '%'.
  std::vector<Word> words(std::string_view text) const {
    std::vector<Word> out;
    std::size_t i = 0;
    const auto skip_space = [&] {
      while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    };
    while (true) {
      skip_space();
      if (i >= text.size()) break;
      const char c = text[i];
      if (c == ';') break;
      if (c == '%' && out.empty()) break;  // tape start/end (%, or FANUC's "%" lines)
      // Block delete: LinuxCNC runs the block unless the operator's switch is on (off by
      // default); eical runs it.
      if (c == '/' && out.empty()) {
        ++i;
        continue;
      }
      if (c == '(') {
        const auto close = text.find(')', i);
        if (close == std::string_view::npos) fail(static_cast<int>(i) + 1, "comment '(' is not closed on this line");
        i = close + 1;
        continue;
      }
      if (!std::isalpha(static_cast<unsigned char>(c)))
        fail(static_cast<int>(i) + 1, "expected a word letter, got '" + std::string(1, c) + "'");
      const int column = static_cast<int>(i) + 1;
      const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      ++i;
      skip_space();
      std::size_t start = i;
      if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
      while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
      std::string number(text.substr(start, i - start));
      if (!number.empty() && number.front() == '+') number.erase(0, 1);
      // from_chars does not take ".5" or "5." forms everywhere; normalise them.
      if (!number.empty() && (number.front() == '.' || (number.size() > 1 && number[0] == '-' && number[1] == '.')))
        number.insert(number.front() == '-' ? 1u : 0u, "0");
      double v = 0.0;
      const auto* first = number.data();
      const auto* last = number.data() + number.size();
      auto [ptr, ec] = std::from_chars(first, last, v);
      if (number.empty() || ec != std::errc() || ptr != last)
        fail(column, "word '" + std::string(1, letter) + "' needs a number");
      out.push_back({letter, v, column});
      if (letter == 'O') {  // a program number; LinuxCNC's O-word subroutines and loops are not
        skip_space();
        if (i < text.size() && std::isalpha(static_cast<unsigned char>(text[i])))
          fail(static_cast<int>(i) + 1,
               "O-word control flow (sub, call, if, while, ...) is not supported; O<n> is read as a program number "
               "only");
      }
    }
    return out;
  }

 private:
  std::string_view name_;
  int line_;
};

bool is_code(double value, double code) { return std::abs(value - code) < 1e-9; }

// The modal state: what a block leaves behind for the next.
struct Modal {
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  Plane plane = Plane::xy;
  bool absolute = true;       // G90
  bool arc_absolute = false;  // G90.1 / G91.1 (LinuxCNC default: incremental I/J/K)
  double unit_mm = 1.0;       // G21; 25.4 after G20
  int motion = -1;            // modal motion G0..G3, -1 = none yet
  double feed_mm_min = 0.0;
};

// One block's words: G- and M-codes in their order, the other words by letter.
struct Block {
  const std::vector<Word>& words;
  std::array<std::optional<Word>, 26> value{};  // non-G/M words by letter
  std::vector<Word> gcodes, mcodes;
  [[nodiscard]] const std::optional<Word>& word(char l) const { return value[static_cast<std::size_t>(l - 'A')]; }
};

Block sort_words(const LineParser& lp, const std::vector<Word>& words) {
  Block b{words, {}, {}, {}};
  for (const Word& w : words) {
    switch (w.letter) {
      case 'G': b.gcodes.push_back(w); break;
      case 'M': b.mcodes.push_back(w); break;
      case 'N': break;  // line number
      case 'O': break;  // program number (FANUC O1000)
      case 'S':
      case 'T': break;  // spindle speed, tool number: no effect on the path (M3/M5/M6 below)
      case 'X':
      case 'Y':
      case 'Z':
      case 'I':
      case 'J':
      case 'K':
      case 'R':
      case 'F':
      case 'P':
      case 'Q': {
        auto& slot = b.value[static_cast<std::size_t>(w.letter - 'A')];
        if (slot) lp.fail(w.column, "word '" + std::string(1, w.letter) + "' appears twice in one block");
        slot = w;
        break;
      }
      default: lp.fail(w.column, "unsupported word '" + std::string(1, w.letter) + "'");
    }
  }
  return b;
}

// What a block's G-codes ask of this block itself; the modal ones change `m` and the program.
struct BlockCodes {
  bool dwell = false;
  int motion = -1;  // G0..G3 in this block, -1 = none
};

BlockCodes apply_gcodes(const LineParser& lp, const Block& b, Modal& m, Program& program) {
  BlockCodes codes;
  for (const Word& g : b.gcodes) {
    const double c = g.value;
    if (is_code(c, 0) || is_code(c, 1) || is_code(c, 2) || is_code(c, 3)) {
      if (codes.motion >= 0) lp.fail(g.column, "two motion G-codes in one block");
      codes.motion = static_cast<int>(std::lround(c));
    } else if (is_code(c, 4))
      codes.dwell = true;
    else if (is_code(c, 17))
      m.plane = Plane::xy;
    else if (is_code(c, 18))
      m.plane = Plane::zx;
    else if (is_code(c, 19))
      m.plane = Plane::yz;
    else if (is_code(c, 20))
      m.unit_mm = 25.4;
    else if (is_code(c, 21))
      m.unit_mm = 1.0;
    else if (is_code(c, 61) || is_code(c, 61.1))
      program.exact_stop = true;
    else if (is_code(c, 64))
      program.exact_stop = false;
    else if (is_code(c, 90))
      m.absolute = true;
    else if (is_code(c, 91))
      m.absolute = false;
    else if (is_code(c, 90.1))
      m.arc_absolute = true;
    else if (is_code(c, 91.1))
      m.arc_absolute = false;
    else if (is_code(c, 94)) {  // units per minute feed: the only feed mode supported
    } else if (is_code(c, 40) || is_code(c, 49) || is_code(c, 80)) {
      // Cutter radius, tool length and canned cycle CANCEL, from a part program's safety
      // line: the state eical simulates (the path of the programmed point).
    } else if (is_code(c, 54)) {
      // The first work coordinate system: the program's coordinates are the set-point.
    } else {
      char buf[32];
      std::snprintf(buf, sizeof buf, "G%g", c);
      lp.fail(g.column, std::string("unsupported G-code ") + buf);
    }
  }
  return codes;
}

// User M-codes (M100..M199) become triggers with their P and Q; the others must be ignorable.
void add_triggers(const LineParser& lp, const Block& b, int line_no, const ParseOptions& options, Program& program) {
  for (const Word& m : b.mcodes) {
    const int code = static_cast<int>(std::lround(m.value));
    if (!is_code(m.value, code)) lp.fail(m.column, "M-code must be an integer");
    if (code >= 100 && code <= 199) {
      program.blocks.emplace_back(
          Trigger{code, b.word('P') ? b.word('P')->value : kNaN, b.word('Q') ? b.word('Q')->value : kNaN});
      program.source.push_back({line_no});
    } else if (std::find(options.ignored_m.begin(), options.ignored_m.end(), code) == options.ignored_m.end()) {
      lp.fail(m.column, "unsupported M-code M" + std::to_string(code));
    }
  }
}

// G4 P<seconds>; a P or Q word needs a dwell or a user M-code to belong to.
void add_dwell(const LineParser& lp, const Block& b, bool dwell, int line_no, Program& program) {
  const bool trigger_in_block =
      std::any_of(b.mcodes.begin(), b.mcodes.end(), [](const Word& m) { return m.value >= 100 && m.value < 200; });
  if (dwell) {
    const auto& p = b.word('P');
    if (!p) lp.fail(b.gcodes.front().column, "G4 needs P<seconds>");
    if (p->value < 0.0) lp.fail(p->column, "dwell P must not be negative");
    program.blocks.emplace_back(Dwell{p->value});
    program.source.push_back({line_no});
  } else if (b.word('P') && !trigger_in_block) {
    lp.fail(b.word('P')->column, "word 'P' without G4 or a user M-code");
  }
  if (b.word('Q') && !trigger_in_block) lp.fail(b.word('Q')->column, "word 'Q' without a user M-code");
}

Eigen::Vector3d target_of(const Block& b, const Modal& m) {
  Eigen::Vector3d target = m.pos;
  for (int a = 0; a < 3; ++a) {
    if (const auto& w = b.word(static_cast<char>('X' + a)))
      target[a] = m.absolute ? w->value * m.unit_mm : m.pos[a] + w->value * m.unit_mm;
  }
  return target;
}

void add_linear(const LineParser& lp, const Block& b, const Modal& m, const Eigen::Vector3d& target, int line_no,
                Program& program) {
  if (b.word('I') || b.word('J') || b.word('K') || b.word('R')) {
    const auto& w = b.word('I') ? b.word('I') : b.word('J') ? b.word('J') : b.word('K') ? b.word('K') : b.word('R');
    lp.fail(w->column, "arc words I/J/K/R need G2 or G3");
  }
  if (m.motion == 1 && m.feed_mm_min <= 0.0) lp.fail(b.words.front().column, "G1 without a feed rate F");
  program.blocks.emplace_back(Linear{m.pos, target, m.feed_mm_min, m.motion == 0});
  program.source.push_back({line_no});
}

// R form: the centre on the chord's normal; the short arc (R > 0) has it left of the chord
// for ccw, right for cw; R < 0 flips.
Eigen::Vector2d r_form_centre(const LineParser& lp, const Word& r, const Eigen::Vector2d& s, const Eigen::Vector2d& e,
                              bool cw, double unit_mm, const ParseOptions& options) {
  const double radius = std::abs(r.value) * unit_mm;
  const Eigen::Vector2d chord = e - s;
  const double d = chord.norm();
  if (d < 1e-12) lp.fail(r.column, "R-form arc needs distinct start and end points");
  if (d / 2.0 > radius + options.arc_radius_tolerance_mm)
    lp.fail(r.column, "arc radius R is smaller than half the chord");
  const double h = std::sqrt(std::max(0.0, radius * radius - d * d / 4.0));
  const Eigen::Vector2d left(-chord.y() / d, chord.x() / d);  // unit normal to the left of the chord
  const double side = (cw ? -1.0 : 1.0) * (r.value < 0.0 ? -1.0 : 1.0);
  return (s + e) / 2.0 + side * h * left;
}

// I/J/K form: offsets from the start (or absolute, G90.1); the end must lie on the circle.
Eigen::Vector2d offset_form_centre(const LineParser& lp, const Block& b, const Modal& m, const PlaneAxes& ax,
                                   const Eigen::Vector2d& s, const Eigen::Vector2d& e, const ParseOptions& options) {
  const std::array<char, 3> offset_letter{'I', 'J', 'K'};
  double off[3] = {0.0, 0.0, 0.0};
  for (int a = 0; a < 3; ++a)
    if (const auto& w = b.word(offset_letter[static_cast<std::size_t>(a)])) {
      if (a == ax.normal) lp.fail(w->column, std::string("offset ") + w->letter + " is normal to the arc plane");
      off[a] = w->value * m.unit_mm;
    }
  const Eigen::Vector2d c =
      m.arc_absolute ? Eigen::Vector2d(off[ax.u], off[ax.v]) : s + Eigen::Vector2d(off[ax.u], off[ax.v]);
  const double r_start = (s - c).norm(), r_end = (e - c).norm();
  if (std::abs(r_start - r_end) > options.arc_radius_tolerance_mm)
    lp.fail(b.words.front().column, "arc end point is not on the circle (radius " + std::to_string(r_start) + " vs " +
                                        std::to_string(r_end) + " mm)");
  if (r_start < 1e-9) lp.fail(b.words.front().column, "arc radius is zero");
  return c;
}

// The signed angle from start to end about the centre: negative for cw; the same point is
// a full turn.
double arc_sweep(const Eigen::Vector2d& s, const Eigen::Vector2d& e, const Eigen::Vector2d& c, bool cw) {
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
void add_arc(const LineParser& lp, const Block& b, const Modal& m, const Eigen::Vector3d& target, int line_no,
             const ParseOptions& options, Program& program) {
  if (m.feed_mm_min <= 0.0) lp.fail(b.words.front().column, "arc without a feed rate F");
  const PlaneAxes ax = axes_of(m.plane);
  const bool cw = m.motion == 2;
  const Eigen::Vector2d s(m.pos[ax.u], m.pos[ax.v]);
  const Eigen::Vector2d e(target[ax.u], target[ax.v]);
  Eigen::Vector2d c;
  if (const auto& r = b.word('R')) {
    if (b.word('I') || b.word('J') || b.word('K')) lp.fail(r->column, "arc with both R and I/J/K");
    c = r_form_centre(lp, *r, s, e, cw, m.unit_mm, options);
  } else {
    c = offset_form_centre(lp, b, m, ax, s, e, options);
  }
  const double sweep = arc_sweep(s, e, c, cw);
  Eigen::Vector3d centre = m.pos;
  centre[ax.u] = c.x();
  centre[ax.v] = c.y();
  program.blocks.emplace_back(Arc{m.pos, target, centre, m.plane, cw, sweep, m.feed_mm_min});
  program.source.push_back({line_no});
}

// One block, executed in LinuxCNC's order: modal G-codes and the feed, user M-codes, dwell,
// then motion.
void parse_block(const LineParser& lp, const std::vector<Word>& words, int line_no, const ParseOptions& options,
                 Modal& m, Program& program) {
  const Block b = sort_words(lp, words);
  const BlockCodes codes = apply_gcodes(lp, b, m, program);
  if (const auto& f = b.word('F')) {
    if (!(f->value > 0.0)) lp.fail(f->column, "feed F must be positive");
    m.feed_mm_min = f->value * m.unit_mm;
  }
  add_triggers(lp, b, line_no, options, program);
  add_dwell(lp, b, codes.dwell, line_no, program);

  if (codes.motion >= 0) m.motion = codes.motion;
  const bool has_axis = b.word('X') || b.word('Y') || b.word('Z');
  const bool has_arc_words = b.word('I') || b.word('J') || b.word('K') || b.word('R');
  if (!has_axis && !has_arc_words) return;
  if (codes.dwell) lp.fail(b.word('X') ? b.word('X')->column : 1, "G4 and a motion in one block");
  if (m.motion < 0) lp.fail(words.front().column, "axis words without a motion mode (G0/G1/G2/G3)");
  const Eigen::Vector3d target = target_of(b, m);
  if (m.motion == 0 || m.motion == 1)
    add_linear(lp, b, m, target, line_no, program);
  else
    add_arc(lp, b, m, target, line_no, options, program);
  m.pos = target;
}

}  // namespace

Program parse(std::string_view text, std::string_view name, const ParseOptions& options) {
  Program program;
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
    const LineParser lp(name, line_no);
    const std::vector<Word> words = lp.words(line);
    if (words.empty()) {
      if (end == text.size()) break;
      continue;
    }
    parse_block(lp, words, line_no, options, modal, program);
  }
  return program;
}

}  // namespace eical::sim::gcode
