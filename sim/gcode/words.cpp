#include "sim/gcode/words.hpp"

#include "dsp/core/error.hpp"

#include <cctype>
#include <charconv>
#include <cmath>

namespace eical::sim::gcode {

void SourceLine::fail(int column, const std::string& what) const {
  throw dsp::InputError(std::string(name_) + ":" + std::to_string(line_) + ":" + std::to_string(column) + ": " + what);
}

namespace {

bool is_alpha(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }
bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

std::string read_as(Dialect d) {
  return std::string("this file is read as ") + dialect_title(d) + " (choose the control with --dialect)";
}

class Splitter {
 public:
  Splitter(std::string_view text, Dialect d, const SourceLine& at) : text_(text), d_(d), at_(at) {}

  std::vector<Word> run() {
    while (true) {
      skip_space();
      if (i_ >= text_.size()) break;
      const char c = text_[i_];
      if (c == ';') break;  // comment (FANUC: end of block) to the end of the line
      if (c == '(') {
        comment();
      } else if (c == '%') {
        if (!percent()) break;
      } else if (c == '*') {
        block_end();
        break;
      } else if (c == '/' && out_.empty()) {
        ++i_;  // block delete: LinuxCNC runs the block unless the operator's switch is on
      } else if (is_alpha(c)) {
        word();
      } else {
        at_.fail(column(), "expected a word letter, got '" + std::string(1, c) + "'");
      }
    }
    return std::move(out_);
  }

 private:
  int column() const { return static_cast<int>(i_) + 1; }
  void skip_space() {
    while (i_ < text_.size() && is_space(text_[i_])) ++i_;
  }

  void comment() {
    if (d_ == Dialect::sinumerik || d_ == Dialect::heidenhain_iso)
      at_.fail(column(), std::string("'(' opens no comment in ") + dialect_title(d_) +
                             " programs (comments start with ';'); " + read_as(d_));
    const auto close = text_.find(')', i_);
    if (close == std::string_view::npos) at_.fail(column(), "comment '(' is not closed on this line");
    i_ = close + 1;
  }

  // False when the rest of the line is done with.
  bool percent() {
    const int col = column();
    const bool line_start = out_.empty() && text_.substr(0, i_).find_first_not_of(" \t") == std::string_view::npos;
    switch (d_) {
      case Dialect::heidenhain_iso:  // "%NAME G71 *": the name is skipped, its words read
        ++i_;
        while (i_ < text_.size() && is_name_char(text_[i_])) ++i_;
        return true;
      case Dialect::sinumerik:  // "%_N_NAME_MPF": the archive's header line
        if (!line_start) at_.fail(col, "'%' starts a header line only");
        return false;
      case Dialect::linuxcnc:
      case Dialect::fanuc: {
        ++i_;
        skip_space();
        if (!line_start || (i_ < text_.size() && text_[i_] != '(' && text_[i_] != ';'))
          at_.fail(col, std::string("a '%' line holds '%' alone in ") + dialect_title(d_) +
                            " programs; '%_N_<NAME>_MPF' begins a SINUMERIK program, '%<NAME> G71 *' a HEIDENHAIN "
                            "ISO one; " +
                            read_as(d_));
        return true;  // a comment may follow
      }
    }
    return false;
  }

  void block_end() {
    if (d_ != Dialect::heidenhain_iso)
      at_.fail(column(), "'*' ends a block in HEIDENHAIN ISO programs; " + read_as(d_));
    const int col = column();
    ++i_;
    skip_space();
    if (i_ < text_.size() && text_[i_] != ';') at_.fail(col, "text after the block end '*'");
  }

  void word() {
    const int col = column();
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text_[i_])));
    ++i_;
    skip_space();
    const std::size_t start = i_;
    if (i_ < text_.size() && (text_[i_] == '+' || text_[i_] == '-')) ++i_;
    while (i_ < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[i_])) || text_[i_] == '.')) ++i_;
    std::string number(text_.substr(start, i_ - start));
    const bool point = number.find('.') != std::string::npos;
    if (!number.empty() && number.front() == '+') number.erase(0, 1);
    // from_chars does not take ".5" or "-.5"; normalise them.
    if (!number.empty() && (number.front() == '.' || (number.size() > 1 && number[0] == '-' && number[1] == '.')))
      number.insert(number.front() == '-' ? 1u : 0u, "0");
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), v);
    if (number.empty() || ec != std::errc() || ptr != number.data() + number.size())
      at_.fail(col, "word '" + std::string(1, letter) + "' needs a number");
    // Beyond any machine (1000 km, 30 years of dwell): refused before a unit or an
    // increment could take it past the range of a double.
    if (std::abs(v) > 1e9) at_.fail(col, "word '" + std::string(1, letter) + "': the number is out of range");
    out_.push_back({letter, v, col, point});
    if (letter == 'O') o_word(col);
  }

  // A program number (FANUC O1000); LinuxCNC's O-words are subroutines, loops and
  // conditions, none of which a calibration runs.
  void o_word(int col) {
    skip_space();
    if (i_ < text_.size() && is_alpha(text_[i_]))
      at_.fail(column(),
               "O-word control flow (sub, call, if, while, ...) is not supported; O<n> is a FANUC program number only");
    if (d_ == Dialect::linuxcnc)
      at_.fail(col, "O<n> is a FANUC program number; in LinuxCNC programs O-words name subroutines; " + read_as(d_));
  }

  std::string_view text_;
  Dialect d_;
  const SourceLine& at_;
  std::size_t i_ = 0;
  std::vector<Word> out_;
};

}  // namespace

std::vector<Word> split_words(std::string_view text, Dialect d, const SourceLine& at) {
  return Splitter(text, d, at).run();
}

}  // namespace eical::sim::gcode
