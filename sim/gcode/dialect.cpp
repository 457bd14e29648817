#include "sim/gcode/dialect.hpp"
#include "sim/gcode/format.hpp"

#include "dsp/core/error.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

namespace eical::sim::gcode {
namespace {

struct WrittenWord {
  char letter;
  std::string text;  // the number as written
  [[nodiscard]] double value() const { return std::stod(text); }
};

struct Line {
  std::vector<WrittenWord> words;
  std::string comment;
};

Line split(const std::string& raw, int line_no) {
  Line l;
  std::size_t i = 0;
  while (i < raw.size()) {
    const char c = raw[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '(') {
      const auto e = raw.find(')', i);
      if (e == std::string::npos)
        throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": unclosed comment");
      l.comment += (l.comment.empty() ? "" : " ") + raw.substr(i + 1, e - i - 1);
      i = e + 1;
    } else if (std::isalpha(static_cast<unsigned char>(c))) {
      WrittenWord w{static_cast<char>(std::toupper(static_cast<unsigned char>(c))), ""};
      ++i;
      while (i < raw.size() &&
             (std::isdigit(static_cast<unsigned char>(raw[i])) || raw[i] == '.' || raw[i] == '-' || raw[i] == '+'))
        w.text += raw[i++];
      if (w.text.empty())
        throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": word '" + std::string(1, w.letter) +
                              "' without a number");
      l.words.push_back(w);
    } else {
      throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": unexpected '" + std::string(1, c) + "'");
    }
  }
  return l;
}

bool is_g(const WrittenWord& w, int code) { return w.letter == 'G' && std::abs(w.value() - code) < 1e-9; }

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Canonical G4 P<seconds> → the dwell value in the dialect's unit.
std::string dwell(const Line& l, int line_no, bool millis) {
  for (const auto& w : l.words)
    if (w.letter == 'P')
      return millis ? std::to_string(std::llround(w.value() * 1000.0)) : format_number("%.3f", w.value());
  throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": G4 without P");
}

bool has_g(const Line& l, int code) {
  for (const auto& w : l.words)
    if (is_g(w, code)) return true;
  return false;
}

std::string join(const std::vector<std::string>& parts) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : " ") + p;
  return s;
}

std::string linuxcnc(const std::vector<Line>&, const std::string& canonical, const ProgramIdentity& id) {
  return "(" + id.title + ")\n" + canonical + "M2\n";
}

// FANUC counts a length without a decimal point in least input increments (X10 is
// 0.010 mm unless parameter 3401#0 is set): every length is written with its point.
std::string fanuc_number(const WrittenWord& w) {
  const bool length = std::string_view("XYZIJKR").find(w.letter) != std::string_view::npos;
  return length && w.text.find('.') == std::string::npos ? w.text + "." : w.text;
}

std::string fanuc(const std::vector<Line>& lines, const ProgramIdentity& id) {
  char head[32];
  std::snprintf(head, sizeof head, "O%04d", id.number);
  std::string out = "%\n" + std::string(head) + " (" + upper(id.title) + ")\n";
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const Line& l = lines[n];
    std::vector<std::string> parts;
    if (has_g(l, 4)) {
      parts = {"G04", "P" + dwell(l, static_cast<int>(n + 1), true)};
    } else {
      for (const auto& w : l.words) parts.push_back(std::string(1, w.letter) + fanuc_number(w));
    }
    if (!l.comment.empty()) parts.push_back("(" + upper(l.comment) + ")");
    if (!parts.empty()) out += join(parts) + "\n";
  }
  return out + "M30\n%\n";
}

std::string sinumerik(const std::vector<Line>& lines, const ProgramIdentity& id) {
  std::string out = "%_N_" + upper(id.name) + "_MPF\n;$PATH=/_N_MPF_DIR\n; " + id.title + "\n";
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const Line& l = lines[n];
    std::vector<std::string> parts;
    if (has_g(l, 4)) {
      parts = {"G4", "F" + dwell(l, static_cast<int>(n + 1), false)};
    } else {
      for (const auto& w : l.words) {
        if (is_g(w, 21))
          parts.push_back("G71");  // metric lengths (the feed is in the metric base system)
        else if (is_g(w, 20))
          parts.push_back("G700");  // inch lengths and feed, as LinuxCNC's G20
        else if (is_g(w, 61))
          parts.push_back("G60");  // exact stop, modal
        else
          parts.push_back(std::string(1, w.letter) + w.text);
      }
    }
    if (!l.comment.empty()) parts.push_back("; " + l.comment);
    if (!parts.empty()) out += join(parts) + "\n";
  }
  return out + "M30\n";
}

// HEIDENHAIN ISO's modal state while a program is translated.
struct HeidenhainModal {
  bool absolute = true;
  int plane = 17;
};

// One G word of a canonical line in HEIDENHAIN ISO: the motion it asks for, a modal word
// written as is, or a refusal naming the line.
void heidenhain_g(const WrittenWord& w, int line_no, int& motion, HeidenhainModal& modal,
                  std::vector<std::string>& parts) {
  const int g = static_cast<int>(std::lround(w.value()));
  if (g >= 0 && g <= 3)
    motion = g;
  else if (g == 90)
    modal.absolute = true, parts.push_back("G90");
  else if (g == 91)
    modal.absolute = false, parts.push_back("G91");
  else if (g == 17 || g == 18 || g == 19)
    modal.plane = g, parts.push_back("G" + std::to_string(g));
  else if (g == 21 || g == 61 || g == 64)
    return;  // mm is in the begin line; no modal exact stop on the TNC
  else if (g == 20)
    throw dsp::InputError("dialect: line " + std::to_string(line_no) +
                          ": inch (G20) has no HEIDENHAIN ISO form here (the begin line says G71, mm)");
  else
    throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": G" + w.text +
                          " has no HEIDENHAIN ISO form here");
}

std::string heidenhain(const std::vector<Line>& lines, const ProgramIdentity& id) {
  const std::string name = upper(id.name);
  std::string out = "%" + name + " G71 *\n";
  int block = 0;
  auto emit = [&](const std::vector<std::string>& parts) {
    block += 10;
    out += "N" + std::to_string(block) + " " + join(parts) + " *\n";
  };
  std::array<double, 3> pos{0.0, 0.0, 0.0};
  HeidenhainModal modal;
  auto signed_num = [](double v) { return format_number("%+.4f", std::abs(v) < 5e-5 ? 0.0 : v); };
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const Line& l = lines[n];
    const int line_no = static_cast<int>(n + 1);
    if (has_g(l, 4)) {
      emit({"G04", "F" + dwell(l, line_no, false)});
      continue;
    }
    int motion = -1;
    std::vector<std::string> parts;
    std::array<std::optional<double>, 3> target{}, centre_offset{};
    for (const auto& w : l.words) {
      if (w.letter == 'G') {
        heidenhain_g(w, line_no, motion, modal, parts);
      } else if (w.letter >= 'X' && w.letter <= 'Z') {
        target[static_cast<std::size_t>(w.letter - 'X')] = w.value();
      } else if (w.letter >= 'I' && w.letter <= 'K') {
        centre_offset[static_cast<std::size_t>(w.letter - 'I')] = w.value();
      } else if (w.letter == 'F' || w.letter == 'M') {
        continue;  // after the motion words
      } else {
        throw dsp::InputError("dialect: line " + std::to_string(line_no) + ": word '" + std::string(1, w.letter) +
                              "' has no HEIDENHAIN ISO form here");
      }
    }
    std::array<double, 3> end = pos;
    for (int a = 0; a < 3; ++a)
      if (target[static_cast<std::size_t>(a)])
        end[static_cast<std::size_t>(a)] =
            modal.absolute ? *target[static_cast<std::size_t>(a)]
                           : pos[static_cast<std::size_t>(a)] + *target[static_cast<std::size_t>(a)];
    if (motion == 2 || motion == 3) {
      if (!modal.absolute)
        throw dsp::InputError("dialect: line " + std::to_string(line_no) +
                              ": an incremental arc has no HEIDENHAIN ISO form here");
      // The circle centre in a block of its own, absolute: canonical I/J/K are offsets
      // from the arc's start (LinuxCNC's default G91.1).
      const int u = modal.plane == 17   ? 0
                    : modal.plane == 18 ? 2
                                        : 1,
                v = modal.plane == 17   ? 1
                    : modal.plane == 18 ? 0
                                        : 2;
      std::vector<std::string> cc;
      for (int a : {u, v})
        cc.push_back(
            std::string(1, static_cast<char>('I' + a)) +
            signed_num(pos[static_cast<std::size_t>(a)] + centre_offset[static_cast<std::size_t>(a)].value_or(0.0)));
      emit(cc);
    }
    if (motion >= 0) parts.push_back("G0" + std::to_string(motion));
    for (int a = 0; a < 3; ++a)
      if (target[static_cast<std::size_t>(a)])
        parts.push_back(std::string(1, static_cast<char>('X' + a)) + signed_num(*target[static_cast<std::size_t>(a)]));
    for (const auto& w : l.words)
      if (w.letter == 'F' || w.letter == 'M') parts.push_back(std::string(1, w.letter) + w.text);
    if (!parts.empty()) emit(parts);
    pos = end;
  }
  return out + "N99999999 %" + name + " G71 *\n";
}

}  // namespace

std::string write_dialect(const std::string& canonical, Dialect d, const ProgramIdentity& id) {
  std::vector<Line> lines;
  std::istringstream is(canonical);
  int n = 0;
  for (std::string raw; std::getline(is, raw);) lines.push_back(split(raw, ++n));
  switch (d) {
    case Dialect::linuxcnc: return linuxcnc(lines, canonical, id);
    case Dialect::fanuc: return fanuc(lines, id);
    case Dialect::sinumerik: return sinumerik(lines, id);
    case Dialect::heidenhain_iso: return heidenhain(lines, id);
  }
  return canonical;
}

}  // namespace eical::sim::gcode
