#pragma once
// Strict reading of TOML configuration files (daemon config, simulation scenarios):
// every key must be known and of the right type; anything else is an error that names
// the file, the line and the key. Unknown keys are caught by finish(), so a typo such as
// `fs_hz` → `fs_Hz` never silently falls back to a default. The one exception is the
// extension namespace (docs/run-files.md): a key beginning with `ext_` (a table named so
// included) belongs to another tool, and every eical reader passes over it.
#include "drivers/config/extension_names.hpp"

#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace eical::drivers {

class StrictTable {
 public:
  // `file` names the source in messages; `section` is the dotted table path ("" = root).
  StrictTable(const toml::table& table, std::string file, std::string section);

  // Parses a whole file; syntax errors become InputError "file:line:col: message".
  static toml::table parse_file(const std::string& path);

  [[nodiscard]] bool has(std::string_view key) const;
  // The keys of this table in file order (e.g. the effect names of a scenario), other
  // tools' ext_ keys left out.
  [[nodiscard]] std::vector<std::string> keys() const;

  double number(std::string_view key);  // required; integers are accepted as numbers
  double number(std::string_view key, double fallback);
  std::int64_t integer(std::string_view key);
  std::int64_t integer(std::string_view key, std::int64_t fallback);
  // An integer that fits an int (counts, bits, priorities): anything beyond is refused
  // rather than narrowed (4294967312 would become 16); ranges are checked by the caller.
  int int32(std::string_view key, int fallback);
  std::string string(std::string_view key);
  std::string string(std::string_view key, std::string fallback);
  // A string that must be one of `allowed`.
  std::string choice(std::string_view key, const std::vector<std::string>& allowed, std::string fallback);
  bool boolean(std::string_view key, bool fallback);
  std::vector<double> numbers(std::string_view key, std::optional<std::size_t> exact_size = std::nullopt);
  std::vector<std::string> strings(std::string_view key);
  // An array of `rows` arrays of `cols` numbers, e.g. a 3x3 mounting matrix.
  std::vector<std::vector<double>> matrix(std::string_view key, std::size_t rows, std::size_t cols);

  // The key's node as it is (nullptr when absent), marked as read: for a value of a type
  // the readers above do not cover (run.toml's `created`, a date-time or a string).
  const toml::node* node(std::string_view key) { return get(key, false); }

  // Sub-table (required or optional) and arrays of tables ([[psd]]).
  StrictTable table(std::string_view key);
  std::optional<StrictTable> optional_table(std::string_view key);
  std::vector<StrictTable> tables(std::string_view key);
  // One table or an array of tables under `key` ([k] or [[k]]: an effect on one axis or several).
  std::vector<StrictTable> table_or_tables(std::string_view key);

  // Throws InputError for the first key that was never asked for (ext_ keys excepted).
  void finish() const;

  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] std::string where(std::string_view key) const;  // "file:line: [section] key"

  // Error for a value that has the right type but is out of range.
  [[noreturn]] void fail(std::string_view key, const std::string& reason) const;

 private:
  const toml::node* get(std::string_view key, bool required);
  const toml::table* table_;
  std::string file_;
  std::string section_;
  std::set<std::string, std::less<>> used_;
};

}  // namespace eical::drivers
