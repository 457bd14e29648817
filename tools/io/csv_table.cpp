#include "tools/io/csv_table.hpp"

#include "drivers/config/extension_names.hpp"
#include "dsp/core/error.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

namespace eical::tools {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  for (;;) {
    const auto comma = line.find(',', pos);
    std::string f = line.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    while (!f.empty() && (f.back() == ' ' || f.back() == '\r')) f.pop_back();
    while (!f.empty() && f.front() == ' ') f.erase(f.begin());
    out.push_back(std::move(f));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

bool known(const std::string& column, const std::vector<std::string>& required,
           const std::vector<std::string>& optional) {
  for (const auto* list : {&required, &optional})
    for (const auto& c : *list)
      if (c == column) return true;
  return false;
}

}  // namespace

CsvTable::CsvTable(const std::filesystem::path& file, const std::vector<std::string>& required,
                   const std::vector<std::string>& optional)
    : file_(file.string()) {
  std::ifstream is(file);
  if (!is) throw dsp::InputError(file_ + ": cannot open");
  std::string line;
  std::size_t no = 0;
  while (std::getline(is, line)) {
    ++no;
    if (line.empty() || line[0] == '#') continue;
    if (header_.empty()) {
      header_ = split(line);
      for (const auto& h : header_)
        if (!known(h, required, optional) && !drivers::is_extension_name(h))
          throw dsp::InputError(file_ + ":" + std::to_string(no) + ": column '" + h +
                                "': unknown column (check the spelling; another tool's columns begin with " +
                                std::string(drivers::kExtensionPrefix) + ")");
      continue;
    }
    auto f = split(line);
    if (f.size() != header_.size())
      throw dsp::InputError(file_ + ":" + std::to_string(no) + ": " + std::to_string(f.size()) +
                            " fields, the header has " + std::to_string(header_.size()));
    cells_.push_back(std::move(f));
    line_.push_back(no);
  }
  if (header_.empty()) throw dsp::InputError(file_ + ": empty file (no header line)");
  for (const auto& r : required) (void)index(r);
  if (cells_.empty()) throw dsp::InputError(file_ + ": no data rows after the header");
}

std::size_t CsvTable::index(const std::string& column) const {
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (header_[i] == column) return i;
  throw dsp::InputError(file_ + ":1: required column '" + column + "' is missing");
}

std::string CsvTable::where(std::size_t row, const std::string& column) const {
  return file_ + ":" + std::to_string(line_[row]) + ": column '" + column + "'";
}

double CsvTable::number(std::size_t row, const std::string& column) const {
  const std::string& s = cells_[row][index(column)];
  double v = 0.0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || p != s.data() + s.size())
    throw dsp::InputError(where(row, column) + ": expected a number, got '" + s + "'");
  if (!std::isfinite(v)) throw dsp::InputError(where(row, column) + ": NaN or Inf");
  return v;
}

long long CsvTable::integer(std::size_t row, const std::string& column) const {
  const std::string& s = cells_[row][index(column)];
  long long v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || p != s.data() + s.size())
    throw dsp::InputError(where(row, column) + ": expected an integer, got '" + s + "'");
  return v;
}

const std::string& CsvTable::text(std::size_t row, const std::string& column) const {
  return cells_[row][index(column)];
}

}  // namespace eical::tools
