#pragma once
// Small strict CSV tables for the command line's inputs (error curves, deviation tables,
// measurement series): a header naming the columns, numbers or words per field, every
// error "file:line: column 'name': reason".
#include <filesystem>
#include <string>
#include <vector>

namespace eical::tools {

class CsvTable {
 public:
  // Reads the file; `required` columns must be in the header (any order), `optional` ones
  // may be; any other column is refused by name (line 1) unless it begins with ext_, the
  // extension namespace of every eical input (docs/run-files.md).
  CsvTable(const std::filesystem::path& file, const std::vector<std::string>& required,
           const std::vector<std::string>& optional = {});

  [[nodiscard]] std::size_t rows() const { return cells_.size(); }
  // A finite number, or InputError naming file, line and column.
  [[nodiscard]] double number(std::size_t row, const std::string& column) const;
  [[nodiscard]] long long integer(std::size_t row, const std::string& column) const;
  [[nodiscard]] const std::string& text(std::size_t row, const std::string& column) const;
  [[nodiscard]] std::string where(std::size_t row, const std::string& column) const;  // "file:line: column 'c'"

 private:
  [[nodiscard]] std::size_t index(const std::string& column) const;
  std::string file_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> cells_;
  std::vector<std::size_t> line_;
};

}  // namespace eical::tools
