#pragma once
// Lines of a text file, plain or gzip-compressed, read in large blocks (no iostream per
// field). Truncation is detected: a gzip stream that ends early is an error naming the
// file, and the caller learns whether the last line ended with a newline.
#include <zlib.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace eical::drivers {

class LineSource {
 public:
  explicit LineSource(const std::filesystem::path& file);  // .gz decides the decoding
  ~LineSource();
  LineSource(const LineSource&) = delete;
  LineSource& operator=(const LineSource&) = delete;

  // Next line without its newline (and without a trailing '\r'); false at the end.
  bool next(std::string_view& line);
  [[nodiscard]] std::size_t line_number() const { return line_no_; }  // 1-based, of the last line returned
  [[nodiscard]] bool last_line_had_newline() const { return last_had_newline_; }
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  bool fill();
  std::string name_;
  gzFile gz_ = nullptr;  // zlib reads plain files transparently too
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false;
  std::size_t line_no_ = 0;
  bool last_had_newline_ = true;
  std::string carry_;
};

}  // namespace eical::drivers
