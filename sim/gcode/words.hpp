#pragma once
// One line of G-code as words, by the control's lexical rules:
//   comments      LinuxCNC "( )" and ";" to the end of the line; FANUC "( )", ";" ends the
//                 block; SINUMERIK and HEIDENHAIN ISO ";" only ("(" opens no comment there)
//   "%" lines     LinuxCNC/FANUC: "%" alone (tape start/end); SINUMERIK: the archive
//                 header "%_N_<NAME>_MPF" (skipped); HEIDENHAIN ISO: "%<NAME>" in the begin
//                 and end blocks ("%NAME G71 *"), whose G70/G71 words are read
//   "*"           HEIDENHAIN ISO block end (nothing but a comment may follow it)
//   "/"           block delete at the start of a block: eical runs the block
//   O<n>          FANUC program number; in LinuxCNC O-words name subroutines (refused)
// Anything else that is not a letter with a number is an InputError naming line and column.
#include "sim/gcode/dialect_id.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace eical::sim::gcode {

struct Word {
  char letter;  // upper case
  double value;
  int column;          // 1-based
  bool decimal_point;  // written with a '.': FANUC reads X10 and X10. differently
};

// Where a line is, for its errors: "<name>:<line>:<column>: <what>".
class SourceLine {
 public:
  SourceLine(std::string_view name, int line) : name_(name), line_(line) {}
  [[noreturn]] void fail(int column, const std::string& what) const;
  [[nodiscard]] int line() const { return line_; }

 private:
  std::string_view name_;
  int line_;
};

std::vector<Word> split_words(std::string_view text, Dialect d, const SourceLine& at);

}  // namespace eical::sim::gcode
